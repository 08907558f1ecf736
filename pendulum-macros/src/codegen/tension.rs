//! `Model::accelerations` by the rod tensions ([`Algorithm::Tension`]): the system
//! `A T = b` of `pendulum_core::rods` (stated and derived once, in that module's docs;
//! 0-based here, the pivot above mass 0), unrolled in the model's own angles, with its
//! per-link constants stored by `new`. It is solved by a twisted factorisation ([`twisted_solve`]: continuants from both ends meeting at the
//! middle row, no division on a serial chain; classical pivots if a continuant leaves
//! `CONTINUANT_RANGE`), then the mass accelerations `a_i = a°_i + (T_{i+1} u_{i+1} − T_i u_i)/m_i`
//! and `ü_i = (a_i − a_{i−1}) / l_i`, mapped to the angles:
//! - planar, `u_i = (sin θ_i, −cos θ_i)`: `F_i = ((σ_i − λ_i θ̇_i) / l_i) (cos θ_i, sin θ_i)`,
//!   `|u̇_i|² = θ̇_i²`, `θ̈_i = (cos θ_i, sin θ_i) · ü_i`, all written in the links' own
//!   frames ([`planar`]);
//! - spatial, `u_i = (sθ cφ, sθ sφ, −cθ)`, `e_θ = (cθ cφ, cθ sφ, sθ)`, `e_φ = (−sφ, cφ, 0)`:
//!   `F_i = (Q_θ e_θ + (Q_φ / sin θ_i) e_φ) / l_i` (`Q_θ = σ_θ − λ θ̇`, `Q_φ = σ_φ − λ sin²θ φ̇`),
//!   `|u̇_i|² = θ̇² + sin²θ φ̇²`, `θ̈ = e_θ·ü + φ̇² sin θ cos θ`,
//!   `φ̈ = (e_φ·ü − 2 θ̇ φ̇ cos θ) / sin θ`.
//!
//! [`Algorithm::Tension`]: crate::plan::Algorithm::Tension

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::guards::{failure, finite_probe};
use super::names::{chart, index, space};
use super::rod_constants::{self, id};
use crate::plan::{Kind, Plan};

/// The first lets of `accelerations`: the inputs, and the sines and cosines of every
/// angle from one call of the vectorised kernel (`trig[a] = [sin q_a, cos q_a]`), its
/// input padded to a multiple of four angles (the kernel's width with AVX2: no scalar
/// tail).
fn prelude(plan: &Plan) -> TokenStream {
    let padded = plan.dof().div_ceil(4) * 4;
    let trig_call = if padded == plan.dof() {
        quote!(::pendulum_core::__private::sin_cos_into(q.as_slice(), &mut trig);)
    } else {
        let (padded, dof) = (index(padded), index(plan.dof()));
        quote! {
            let mut angles = [0.0f64; #padded];
            angles[..#dof].copy_from_slice(q.as_slice());
            ::pendulum_core::__private::sin_cos_into(&angles, &mut trig);
        }
    };
    let trig_len = index(padded);
    quote! {
        let torque = &inputs.torque;
        let pivot = &inputs.pivot_acceleration;
        let mut trig = [[0.0f64; 2]; #trig_len];
        #trig_call
    }
}

/// `fn accelerations` with `body` (which ends in the lets of `outputs`, the q̈ entries):
/// the failure path, and the finiteness probe before the results are written.
fn wrap(plan: &Plan, body: TokenStream, outputs: &[TokenStream]) -> TokenStream {
    let dof = index(plan.dof());
    let space = space(plan);
    let failure = failure(plan);
    let probe = finite_probe(outputs);
    let out_index = (0..plan.dof()).map(index);
    quote! {
        fn accelerations(
            &self,
            q: &SVector<f64, #dof>,
            qd: &SVector<f64, #dof>,
            inputs: &Inputs<Const<#dof>, #space>,
            out: &mut SVector<f64, #dof>,
        ) -> Result<()> {
            #failure
            #body
            if #probe != 0.0 {
                return Err(failure(q, qd, inputs, Error::NonFiniteAccelerations));
            }
            #(out[#out_index] = #outputs;)*
            Ok(())
        }
    }
}

/// The planar route in the links' own frames: with `n_i = (cos θ_i, sin θ_i)`,
/// `C_i = u_{i−1}·u_i = n_{i−1}·n_i = cos(θ_i − θ_{i−1})` and
/// `S_i = n_{i−1}·u_i = sin(θ_i − θ_{i−1})`, and the pulls `f_i = σ_i/l_i − (λ_i/l_i) θ̇_i`
/// (`F_i = f_i n_i`; `f_n = T_n = 0`), the module docs' system and accelerations reduce to
/// ```text
/// b_i = l_i θ̇_i² + f_{i+1} S_{i+1}/m_i − f_{i−1} S_i/m_{i−1}      (i ≥ 1)
/// b_0 = l_0 θ̇_0² + u_0·(g⃗ − p̈) + f_1 S_1/m_0,   c_i = −C_i/m_{i−1}
/// θ̈_i = ((f_i − f_{i+1} C_{i+1} + T_{i+1} S_{i+1})/m_i − (f_{i−1} C_i − f_i + T_{i−1} S_i)/m_{i−1}) / l_i
/// θ̈_0 = ((f_0 − f_1 C_1 + T_1 S_1)/m_0 − n_0·(p̈ − g⃗)) / l_0
/// ```
/// (gravity cancels from every row but the first): no Cartesian accelerations at all.
///
/// Written once, as the body of `PlanarKernel::kernel` over any lane type `V`
/// (`pendulum_core::batch`): `accelerations` runs it on `f64` ([`planar_accelerations`]),
/// `UnrolledBatch` on four chains at once.
fn planar_kernel(plan: &Plan) -> TokenStream {
    let n = plan.links;
    let lane = quote!(V);
    let mut body = rod_constants::locals(plan, &quote!(c), &lane);
    body.extend(quote! {
        let [pa_x, pa_y] = pivot;
    });
    for i in 0..n {
        let (st, ct, dth, pull) = (id("st", i), id("ct", i), id("dth", i), id("pull", i));
        let ii = index(i);
        let (il, drag) = (field("rod_il", i), field("rod_drag", i));
        body.extend(quote! {
            let [#st, #ct] = trig[#ii];
            let #dth = rates[#ii];
            let #pull = torque[#ii] * #il - #drag * #dth;
        });
        if i >= 1 {
            let (c, sd, st1, ct1) = (id("cd", i), id("sd", i), id("st", i - 1), id("ct", i - 1));
            let (off, im_above) = (id("off", i), field("rod_im", i - 1));
            body.extend(quote! {
                let #c = #ct1 * #ct + #st1 * #st;
                let #sd = #st * #ct1 - #ct * #st1;
                let #off = -#c * #im_above;
            });
        }
    }
    for i in 0..n {
        let (b, l, dth, im) = (id("b", i), field("rod_l", i), id("dth", i), field("rod_im", i));
        let mut terms = vec![quote!(#l * #dth * #dth)];
        if i == 0 {
            let (st, ct) = (id("st", 0), id("ct", 0));
            // u_0·(g⃗ − p̈) with u_0 = (sin θ_0, −cos θ_0), g⃗ = (0, −g).
            terms.push(quote!(#ct * (g + pa_y) - #st * pa_x));
        } else {
            let (pull_above, sd, im_above) = (id("pull", i - 1), id("sd", i), field("rod_im", i - 1));
            terms.push(quote!(-#pull_above * #sd * #im_above));
        }
        if i + 1 < n {
            let (pull_below, sd_below) = (id("pull", i + 1), id("sd", i + 1));
            terms.push(quote!(#pull_below * #sd_below * #im));
        }
        body.extend(quote!(let #b = #(#terms)+*;));
    }
    body.extend(twisted_solve(n, &lane));
    let mut outputs = Vec::new();
    for i in 0..n {
        let (x, pull, im, il) = (id("x_th", i), id("pull", i), field("rod_im", i), field("rod_il", i));
        // (f_i − f_{i+1} C_{i+1} + T_{i+1} S_{i+1}) / m_i
        let own = if i + 1 < n {
            let (pull_below, cd, sd, t_below) =
                (id("pull", i + 1), id("cd", i + 1), id("sd", i + 1), id("t", i + 1));
            quote!((#pull - #pull_below * #cd + #t_below * #sd) * #im)
        } else {
            quote!(#pull * #im)
        };
        let above = if i == 0 {
            let (st, ct) = (id("st", 0), id("ct", 0));
            // n_0·(p̈ − g⃗) with n_0 = (cos θ_0, sin θ_0).
            quote!((#ct * pa_x + #st * (pa_y + g)))
        } else {
            let (pull_above, cd, sd, t_above, im_above) =
                (id("pull", i - 1), id("cd", i), id("sd", i), id("t", i - 1), field("rod_im", i - 1));
            quote!((#pull_above * #cd - #pull + #t_above * #sd) * #im_above)
        };
        body.extend(quote!(let #x = (#own - #above) * #il;));
        outputs.push(x);
    }
    quote!({ #body [#(#outputs),*] })
}

/// `impl PlanarKernel<n>` ([`planar_kernel`]) for a planar tension model, or
/// `impl SpatialKernel<n>` ([`spatial_kernel`]) for a spatial one.
pub(super) fn kernel_impl(name: &Ident, plan: &Plan) -> TokenStream {
    let n = index(plan.links);
    let body = match plan.kind {
        Kind::Planar => planar_kernel(plan),
        Kind::Spatial => spatial_kernel(plan),
    };
    let (trait_name, signature, row_accelerations) = match plan.kind {
        Kind::Planar => (
            quote!(PlanarKernel),
            quote! {
                fn kernel<V: ::pendulum_core::lanes::Lane>(
                    c: &::pendulum_core::batch::LinkConstants<V, #n>,
                    trig: &[[V; 2]; #n],
                    rates: &[V; #n],
                    torque: &[V; #n],
                    pivot: [V; 2],
                ) -> [V; #n]
            },
            quote!(),
        ),
        Kind::Spatial => (
            quote!(SpatialKernel),
            quote! {
                fn kernel<V: ::pendulum_core::lanes::Lane>(
                    c: &::pendulum_core::batch::LinkConstants<V, #n>,
                    trig: &[[[V; 2]; #n]; 2],
                    rates: &[[V; #n]; 2],
                    torque: &[[V; #n]; 2],
                    pivot: [V; 3],
                ) -> [[V; #n]; 2]
            },
            quote! {
                fn row_accelerations(
                    &self,
                    q: &[f64],
                    qd: &[f64],
                    torque: &[f64],
                    pivot: [f64; 3],
                    out: &mut [f64],
                ) -> Result<()> {
                    let inputs = Inputs {
                        torque: SVector::from_column_slice(torque),
                        pivot_acceleration: SVector::from(pivot),
                    };
                    let mut result = SVector::zeros();
                    let (q, qd) = (SVector::from_column_slice(q), SVector::from_column_slice(qd));
                    Model::accelerations(self, &q, &qd, &inputs, &mut result)?;
                    out.copy_from_slice(result.as_slice());
                    Ok(())
                }
            },
        ),
    };
    let chart = chart(plan);
    quote! {
        #[automatically_derived]
        impl ::pendulum_core::batch::Generated<#n> for #name {
            type Chart = ::pendulum_core::kinematics::#chart;

            fn constants(&self) -> &::pendulum_core::batch::LinkConstants<f64, #n> {
                &self.rods
            }
        }

        #[automatically_derived]
        #[allow(clippy::suboptimal_flops, clippy::eq_op)]
        impl ::pendulum_core::batch::#trait_name<#n> for #name {
            #row_accelerations

            #[inline(always)]
            #signature
            #body
        }
    }
}

/// The planar `fn accelerations`: the sines and cosines, then [`planar_kernel`] on `f64`.
fn planar_accelerations(plan: &Plan) -> TokenStream {
    let n = index(plan.links);
    let mut body = prelude(plan);
    let outputs: Vec<TokenStream> = (0..plan.links)
        .map(|i| {
            let x = id("x_th", i);
            quote!(#x)
        })
        .collect();
    body.extend(quote! {
        let trig: [[f64; 2]; #n] = ::core::array::from_fn(|i| trig[i]);
        let [#(#outputs),*] = <Self as ::pendulum_core::batch::PlanarKernel<#n>>::kernel::<f64>(
            &self.rods,
            &trig,
            &qd.data.0[0],
            &torque.data.0[0],
            [pivot[0], pivot[1]],
        );
    });
    wrap(plan, body, &outputs)
}

/// `fn accelerations` by the rod tensions (module docs): [`planar`] or [`spatial`].
pub(super) fn accelerations(plan: &Plan) -> TokenStream {
    match plan.kind {
        Kind::Planar => planar_accelerations(plan),
        Kind::Spatial => spatial_accelerations(plan),
    }
}

/// `<name>[i]`: a per-link constant stored by `new`, by its local name
/// ([`rod_constants::locals`]).
fn field(name: &str, i: usize) -> TokenStream {
    let (f, i) = (format_ident!("{name}"), index(i));
    quote!(#f[#i])
}

/// The spatial route in Cartesian components (module docs): directions, force pairs and
/// free accelerations per link, the tension solve, then `ü_i` mapped to `(θ̈_i, φ̈_i)`.
///
/// Written once, as the body of `SpatialKernel::kernel` over any lane type `V`
/// (`pendulum_core::batch`): `accelerations` runs it on `f64` after checking every polar
/// sine ([`spatial_accelerations`]), `UnrolledSpatialBatch` on four or eight chains at once.
fn spatial_kernel(plan: &Plan) -> TokenStream {
    let n = plan.links;
    const XYZ: [&str; 3] = ["x", "y", "z"];
    let u = |c: &str, i: usize| id(&format!("u{c}"), i);
    let f = |c: &str, i: usize| id(&format!("f{c}"), i);
    let free = |c: &str, i: usize| id(&format!("free_{c}"), i);
    let a = |c: &str, i: usize| id(&format!("a_{c}"), i);
    let pivot_names: Vec<Ident> = XYZ.iter().map(|c| format_ident!("pa_{c}")).collect();
    let lane = quote!(V);
    let mut body = rod_constants::locals(plan, &quote!(c), &lane);
    body.extend(quote! {
        let [#(#pivot_names),*] = pivot;
        let two = <V as ::pendulum_core::lanes::Lane>::splat(2.0);
        let [polar, azimuth] = trig;
    });
    // The links' directions, rates and force pairs.
    for i in 0..n {
        let (st, ct, dth, sp, cp, dph, is) =
            (id("st", i), id("ct", i), id("dth", i), id("sp", i), id("cp", i), id("dph", i), id("is", i));
        let ii = index(i);
        let (il, drag) = (field("rod_il", i), field("rod_drag", i));
        let (rate2, pull, pull_ph) = (id("rate2_", i), id("pull_th", i), id("pull_ph", i));
        let [ux, uy, uz] = [u("x", i), u("y", i), u("z", i)];
        let [fx, fy, fz] = [f("x", i), f("y", i), f("z", i)];
        let (etx, ety) = (id("etx", i), id("ety", i));
        body.extend(quote! {
            let [#st, #ct] = polar[#ii];
            let [#sp, #cp] = azimuth[#ii];
            let #dth = rates[0][#ii];
            let #dph = rates[1][#ii];
            let #is = one / #st;
            let #ux = #st * #cp;
            let #uy = #st * #sp;
            let #uz = -#ct;
            let #etx = #ct * #cp;
            let #ety = #ct * #sp;
            let #rate2 = #dth * #dth + #st * #st * #dph * #dph;
            let #pull = torque[0][#ii] * #il - #drag * #dth;
            let #pull_ph = torque[1][#ii] * #il * #is - #drag * #st * #dph;
            let #fx = #pull * #etx - #pull_ph * #sp;
            let #fy = #pull * #ety + #pull_ph * #cp;
            let #fz = #pull * #st;
        });
    }

    // Free accelerations a°_i and right-hand sides b_i.
    for i in 0..n {
        let im = field("rod_im", i);
        let mut dot = Vec::new();
        for (k, c) in XYZ.iter().enumerate() {
            let (fa, fi) = (free(c, i), f(c, i));
            let gravity = if k == 2 { quote!(-g +) } else { quote!() };
            let pair = if i + 1 < n {
                let below = f(c, i + 1);
                quote!((#fi - #below))
            } else {
                quote!(#fi)
            };
            body.extend(quote!(let #fa = #gravity #pair * #im;));
            let above = if i == 0 { pivot_names[k].clone() } else { free(c, i - 1) };
            let ui = u(c, i);
            dot.push(quote!(#ui * (#fa - #above)));
        }
        let (b, l, rate2) = (id("b", i), field("rod_l", i), id("rate2_", i));
        body.extend(quote!(let #b = #l * #rate2 #(+ #dot)*;));
    }
    for i in 1..n {
        let (c, im_above) = (id("off", i), field("rod_im", i - 1));
        let products = XYZ.iter().map(|k| {
            let (a, b) = (u(k, i - 1), u(k, i));
            quote!(#a * #b)
        });
        body.extend(quote!(let #c = -(#(#products)+*) * #im_above;));
    }
    body.extend(twisted_solve(n, &lane));

    // Mass accelerations a_i, link accelerations ü_i, angle accelerations.
    for i in (0..n).rev() {
        let (t, im) = (id("t", i), field("rod_im", i));
        for c in XYZ {
            let (ai, fa, ui) = (a(c, i), free(c, i), u(c, i));
            let pull_below = if i + 1 < n {
                let (t_below, u_below) = (id("t", i + 1), u(c, i + 1));
                quote!(#t_below * #u_below -)
            } else {
                quote!(-)
            };
            body.extend(quote!(let #ai = #fa + (#pull_below #t * #ui) * #im;));
        }
    }
    let (mut polar, mut azimuthal) = (Vec::new(), Vec::new());
    for i in 0..n {
        let il = field("rod_il", i);
        let [wx, wy, wz] = XYZ.map(|c| id(&format!("udd_{c}"), i));
        for (k, (c, w)) in XYZ.iter().zip([&wx, &wy, &wz]).enumerate() {
            let ai = a(c, i);
            let above = if i == 0 { pivot_names[k].clone() } else { a(c, i - 1) };
            body.extend(quote!(let #w = (#ai - #above) * #il;));
        }
        let (st, ct, sp, cp, dth, dph, is, etx, ety) = (
            id("st", i),
            id("ct", i),
            id("sp", i),
            id("cp", i),
            id("dth", i),
            id("dph", i),
            id("is", i),
            id("etx", i),
            id("ety", i),
        );
        let (x_th, x_ph) = (id("x_th", i), id("x_ph", i));
        body.extend(quote! {
            let #x_th = #etx * #wx + #ety * #wy + #st * #wz + #dph * #dph * #st * #ct;
            let #x_ph = (#cp * #wy - #sp * #wx - two * #dth * #dph * #ct) * #is;
        });
        polar.push(x_th);
        azimuthal.push(x_ph);
    }
    quote!({ #body [[#(#polar),*], [#(#azimuthal),*]] })
}

/// The spatial `fn accelerations`: the sines and cosines, every link's polar sine checked
/// (`check_polar_sin`, in link order), then [`spatial_kernel`] on `f64`.
fn spatial_accelerations(plan: &Plan) -> TokenStream {
    let n = plan.links;
    let links = index(n);
    let mut body = prelude(plan);
    for i in 0..n {
        let (th, link, st) = (index(i), index(i + 1), id("st", i));
        body.extend(quote! {
            let [#st, _] = trig[#th];
            if let Err(error) = ::pendulum_core::check_polar_sin(#link, q[#th], #st) {
                return Err(failure(q, qd, inputs, error));
            }
        });
    }
    let polar: Vec<Ident> = (0..n).map(|i| id("x_th", i)).collect();
    let azimuthal: Vec<Ident> = (0..n).map(|i| id("x_ph", i)).collect();
    body.extend(quote! {
        let both = |v: &[f64]| -> [[f64; #links]; 2] {
            [::core::array::from_fn(|i| v[i]), ::core::array::from_fn(|i| v[#links + i])]
        };
        let trig: [[[f64; 2]; #links]; 2] =
            [::core::array::from_fn(|i| trig[i]), ::core::array::from_fn(|i| trig[#links + i])];
        let [[#(#polar),*], [#(#azimuthal),*]] =
            <Self as ::pendulum_core::batch::SpatialKernel<#links>>::kernel::<f64>(
                &self.rods,
                &trig,
                &both(qd.as_slice()),
                &both(torque.as_slice()),
                [pivot[0], pivot[1], pivot[2]],
            );
    });
    let outputs: Vec<TokenStream> = polar.iter().chain(&azimuthal).map(|x| quote!(#x)).collect();
    wrap(plan, body, &outputs)
}

/// The lets of the tension solve `A T = b` (module docs), given the lets `b<i>` and the
/// off-diagonal entries `off<i>` = `c_i = A_{i,i−1} = −(u_{i−1}·u_i)/m_{i−1}`: a twisted
/// factorisation that eliminates
/// from both ends at once and meets at the middle row `k = ⌊n/2⌋`, so that each serial
/// chain is half the chain long. Continuants from the top, `P_i = A_ii P_{i−1} − c_i² P_{i−2}`
/// (`P_{−1} = 1`, rows `i < k`), and from the bottom, `Q_i = A_ii Q_{i+1} − c_{i+1}² Q_{i+2}`
/// (`Q_n = 1`, rows `i > k`), with the right-hand sides eliminated in the same scaling,
/// `Y_i = b_i P_{i−1} − c_i Y_{i−1}` and `Z_i = b_i Q_{i+1} − c_{i+1} Z_{i+1}`:
/// ```text
/// T_k = (b_k − c_k Y_{k−1}/P_{k−1} − c_{k+1} Z_{k+1}/Q_{k+1})
///         / (A_kk − c_k² P_{k−2}/P_{k−1} − c_{k+1}² Q_{k+2}/Q_{k+1})
/// T_i = (Y_i − c_{i+1} P_{i−1} T_{i+1}) / P_i   (i < k, upwards)
/// T_i = (Z_i − c_i Q_{i+1} T_{i−1}) / Q_i       (i > k, downwards)
/// ```
/// No division on a serial chain. Should a continuant leave `CONTINUANT_RANGE`, the
/// tensions come from the classical elimination instead ([`pivots`]), in the lanes whose
/// continuants do (`lane`: the number type, `f64` or the kernel's `V`).
fn twisted_solve(n: usize, lane: &TokenStream) -> TokenStream {
    let mut out = TokenStream::new();
    let off = |i: usize| id("off", i);
    let k = n / 2;
    let (p, q, y, z, rp, rq) = (
        |i: usize| id("p", i),
        |i: usize| id("q", i),
        |i: usize| id("yt", i),
        |i: usize| id("zb", i),
        |i: usize| id("rp", i),
        |i: usize| id("rq", i),
    );
    let b = |i: usize| id("b", i);
    // Top rows 0..k and bottom rows k+1..n, interleaved so that both chains are in flight.
    let mut hot = TokenStream::new();
    let top: Vec<usize> = (0..k).collect();
    let bottom: Vec<usize> = (k + 1..n).rev().collect();
    for step in 0..top.len().max(bottom.len()) {
        if let Some(&i) = top.get(step) {
            let (pi, yi, bi, d) = (p(i), y(i), b(i), field("rod_diag", i));
            let value = match i {
                0 => quote!(#d),
                1 => {
                    let (p1, c) = (p(0), off(1));
                    quote!(#d * #p1 - #c * #c)
                }
                _ => {
                    let (p1, p2, c) = (p(i - 1), p(i - 2), off(i));
                    quote!(#d * #p1 - (#c * #c) * #p2)
                }
            };
            hot.extend(quote!(let #pi = #value;));
            if i == 0 {
                hot.extend(quote!(let #yi = #bi;));
            } else {
                let (p1, y1, c) = (p(i - 1), y(i - 1), off(i));
                hot.extend(quote!(let #yi = #bi * #p1 - #c * #y1;));
            }
        }
        if let Some(&i) = bottom.get(step) {
            let (qi, zi, bi, d) = (q(i), z(i), b(i), field("rod_diag", i));
            let value = if i + 1 == n {
                quote!(#d)
            } else if i + 2 == n {
                let (q1, c) = (q(i + 1), off(i + 1));
                quote!(#d * #q1 - #c * #c)
            } else {
                let (q1, q2, c) = (q(i + 1), q(i + 2), off(i + 1));
                quote!(#d * #q1 - (#c * #c) * #q2)
            };
            hot.extend(quote!(let #qi = #value;));
            if i + 1 == n {
                hot.extend(quote!(let #zi = #bi;));
            } else {
                let (q1, z1, c) = (q(i + 1), z(i + 1), off(i + 1));
                hot.extend(quote!(let #zi = #bi * #q1 - #c * #z1;));
            }
        }
    }
    for &i in &top {
        let (r, pi) = (rp(i), p(i));
        hot.extend(quote!(let #r = one / #pi;));
    }
    for &i in &bottom {
        let (r, qi) = (rq(i), q(i));
        hot.extend(quote!(let #r = one / #qi;));
    }
    // The twist row.
    let (dk, bk, tk) = (field("rod_diag", k), b(k), id("t", k));
    let mut pivot = quote!(#dk);
    let mut rhs = quote!(#bk);
    if k >= 1 {
        let (c, y1, r1) = (off(k), y(k - 1), rp(k - 1));
        let p2 = if k >= 2 {
            let p2 = p(k - 2);
            quote!(* #p2)
        } else {
            quote!()
        };
        pivot = quote!(#pivot - (#c * #c) #p2 * #r1);
        rhs = quote!(#rhs - #c * #y1 * #r1);
    }
    if k + 1 < n {
        let (c, z1, r1) = (off(k + 1), z(k + 1), rq(k + 1));
        let q2 = if k + 2 < n {
            let q2 = q(k + 2);
            quote!(* #q2)
        } else {
            quote!()
        };
        pivot = quote!(#pivot - (#c * #c) #q2 * #r1);
        rhs = quote!(#rhs - #c * #z1 * #r1);
    }
    hot.extend(quote!(let #tk = (#rhs) / (#pivot);));
    // Outwards from the twist, both directions at once.
    let steps = k.max(n - 1 - k);
    for step in 1..=steps {
        if step <= k {
            let i = k - step;
            let (ti, t1, yi, r, c) = (id("t", i), id("t", i + 1), y(i), rp(i), off(i + 1));
            let scale = if i >= 1 {
                let p1 = p(i - 1);
                quote!(#c * #p1 * #r)
            } else {
                quote!(#c * #r)
            };
            hot.extend(quote!(let #ti = #yi * #r - #scale * #t1;));
        }
        if k + step < n {
            let i = k + step;
            let (ti, t1, zi, r, c) = (id("t", i), id("t", i - 1), z(i), rq(i), off(i));
            let scale = if i + 1 < n {
                let q1 = q(i + 1);
                quote!(#c * #q1 * #r)
            } else {
                quote!(#c * #r)
            };
            hot.extend(quote!(let #ti = #zi * #r - #scale * #t1;));
        }
    }
    let continuants: Vec<Ident> = top.iter().map(|&i| p(i)).chain(bottom.iter().map(|&i| q(i))).collect();
    let ts: Vec<Ident> = (0..n).map(|i| id("t", i)).collect();
    let diags: Vec<TokenStream> = (0..n).map(|i| field("rod_diag", i)).collect();
    let offs: Vec<TokenStream> = (0..n)
        .map(|i| {
            if i == 0 {
                quote!(zero)
            } else {
                let c = off(i);
                quote!(#c)
            }
        })
        .collect();
    let bs: Vec<Ident> = (0..n).map(b).collect();
    let t_index = (0..n).map(index);
    let fallback = pivots(n);
    out.extend(quote! {
        #fallback
        let (#(#ts,)*) = {
            #hot
            let outside = <#lane as ::pendulum_core::lanes::Lane>::none();
            #(let outside = <#lane as ::pendulum_core::lanes::Lane>::or(
                outside,
                ::pendulum_core::lanes::Lane::continuant_outside(#continuants),
            );)*
            if <#lane as ::pendulum_core::lanes::Lane>::any(outside) {
                let t = pivots([#(#diags),*], [#(#offs),*], [#(#bs),*]);
                (#(<#lane as ::pendulum_core::lanes::Lane>::select(outside, t[#t_index], #ts),)*)
            } else {
                (#(#ts,)*)
            }
        };
    });
    out
}

/// `fn pivots` inside `accelerations`: the tensions by classical pivots
/// `D_i = A_ii − c_i² / D_{i−1}` and back substitution (divisions on the serial chain, but
/// no continuant to leave its range), for the chains (lanes) whose continuants do;
/// straight-line like the rest.
fn pivots(n: usize) -> TokenStream {
    let links = index(n);
    let mut body = TokenStream::new();
    for i in 0..n {
        let ii = index(i);
        let (ip, e, s) = (id("ip", i), id("e", i), id("s", i));
        if i == 0 {
            body.extend(quote! {
                let #ip = one / diagonal[0];
                let #e = rhs[0];
            });
        } else {
            let (fac, ip_above, e_above) = (id("fac", i), id("ip", i - 1), id("e", i - 1));
            body.extend(quote! {
                let #fac = off[#ii] * #ip_above;
                let #ip = one / (diagonal[#ii] - #fac * off[#ii]);
                let #e = rhs[#ii] - #fac * #e_above;
            });
        }
        body.extend(quote!(let #s = #e * #ip;));
    }
    for i in (0..n).rev() {
        let (t, s) = (id("t", i), id("s", i));
        if i + 1 == n {
            body.extend(quote!(let #t = #s;));
        } else {
            let (fac, t_below) = (id("fac", i + 1), id("t", i + 1));
            body.extend(quote!(let #t = #s - #fac * #t_below;));
        }
    }
    let ts = (0..n).map(|i| id("t", i));
    quote! {
        /// The tensions by classical pivots and back substitution, for chains whose
        /// continuants leave `CONTINUANT_RANGE`.
        #[cold]
        #[inline(never)]
        fn pivots<V: ::pendulum_core::lanes::Lane>(
            diagonal: [V; #links],
            off: [V; #links],
            rhs: [V; #links],
        ) -> [V; #links] {
            let one = V::splat(1.0);
            #body
            [#(#ts),*]
        }
    }
}
