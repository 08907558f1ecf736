//! `Model::accelerations` by the rod tensions ([`Algorithm::Tension`]): the O(n) solve of
//! `pendulum_core::PlanarTension` and `Directions` (the `rods` module docs there), unrolled
//! in the model's own angles, with its per-link constants stored by `new`.
//!
//! Mass `i` (0-based, the pivot `p` above mass 0) sits at `r_i = r_{i−1} + l_i u_i`. With the
//! free accelerations `a°_i = g⃗ + (F_i − F_{i+1}) / m_i` (`a°_{−1} = p̈`, `F_i` the force
//! pair of the generalized forces on rod `i`), the tensions solve the symmetric
//! tridiagonal system
//! ```text
//! (1/m_i + 1/m_{i−1}) T_i − (u_{i−1}·u_i / m_{i−1}) T_{i−1} − (u_i·u_{i+1} / m_i) T_{i+1}
//!     = l_i |u̇_i|² + u_i · (a°_i − a°_{i−1})
//! ```
//! by continuants (`P_i = A_ii P_{i−1} − A_{i,i−1}² P_{i−2}`, pivots `P_i / P_{i−1}`: no
//! division on the serial chain; classical pivots if a continuant leaves
//! `CONTINUANT_RANGE`), then the mass accelerations `a_i = a°_i + (T_{i+1} u_{i+1} − T_i u_i)/m_i`
//! and `ü_i = (a_i − a_{i−1}) / l_i`, mapped to the angles:
//! - planar, `u_i = (sin θ_i, −cos θ_i)`: `F_i = ((σ_i − λ_i θ̇_i) / l_i) (cos θ_i, sin θ_i)`,
//!   `|u̇_i|² = θ̇_i²`, `θ̈_i = (cos θ_i, sin θ_i) · ü_i`;
//! - spatial, `u_i = (sθ cφ, sθ sφ, −cθ)`, `e_θ = (cθ cφ, cθ sφ, sθ)`, `e_φ = (−sφ, cφ, 0)`:
//!   `F_i = (Q_θ e_θ + (Q_φ / sin θ_i) e_φ) / l_i` (`Q_θ = σ_θ − λ θ̇`, `Q_φ = σ_φ − λ sin²θ φ̇`),
//!   `|u̇_i|² = θ̇² + sin²θ φ̇²`, `θ̈ = e_θ·ü + φ̇² sin θ cos θ`,
//!   `φ̈ = (e_φ·ü − 2 θ̇ φ̇ cos θ) / sin θ`.
//!
//! [`Algorithm::Tension`]: crate::plan::Algorithm::Tension

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::accelerations::{failure, finite_probe};
use super::{index, space};
use crate::plan::{Kind, Plan};

/// `name` with the link index appended: `st3`.
fn id(name: &str, i: usize) -> Ident {
    format_ident!("{name}{i}")
}

/// The per-link constants `accelerations` reads, as `(field, its value in new from the
/// lets m<i>, l<i>, lam<i>, doc)`: `1/m_i`, `l_i`, `1/l_i`, `λ_i/l_i` and the diagonal
/// `1/m_i + 1/m_{i−1}` of the tension system.
pub(super) fn stored(plan: &Plan) -> Vec<(Ident, TokenStream, String)> {
    let mut fields = Vec::new();
    for i in 0..plan.links {
        let (m, l, lam) = (id("m", i), id("l", i), id("lam", i));
        fields.push((id("rod_im", i), quote!(1.0 / #m), format!(" `1/m_{i}` (0-based), 1/kg.")));
        fields.push((id("rod_l", i), quote!(#l), format!(" `l_{i}` (0-based), m.")));
        fields.push((id("rod_il", i), quote!(1.0 / #l), format!(" `1/l_{i}` (0-based), 1/m.")));
        fields.push((id("rod_drag", i), quote!(#lam / #l), format!(" `λ_{i}/l_{i}` (0-based), N·s.")));
        let diagonal = if i == 0 {
            quote!(1.0 / #m)
        } else {
            let above = id("m", i - 1);
            quote!(1.0 / #m + 1.0 / #above)
        };
        let doc = if i == 0 {
            " `1/m_0` (0-based), 1/kg: the tension system's first diagonal entry.".to_owned()
        } else {
            format!(" `1/m_{i} + 1/m_{}` (0-based), 1/kg: the tension system's diagonal.", i - 1)
        };
        fields.push((id("rod_diag", i), diagonal, doc));
    }
    fields
}

/// The lets `new` needs for [`stored`]: `m<i>`, `l<i>`, `lam<i>` from the chain.
pub(super) fn constructor_lets(plan: &Plan) -> TokenStream {
    let n = plan.links;
    let (m, l, lam) = ((0..n).map(|i| id("m", i)), (0..n).map(|i| id("l", i)), (0..n).map(|i| id("lam", i)));
    let idx = (0..n).map(index).collect::<Vec<_>>();
    quote! {
        let masses = chain.masses();
        let lengths = chain.lengths();
        let damping = chain.damping();
        #(let #m = masses[#idx];)*
        #(let #l = lengths[#idx];)*
        #(let #lam = damping[#idx];)*
    }
}

/// `fn accelerations` by the rod tensions (module docs).
pub(super) fn accelerations(plan: &Plan) -> TokenStream {
    let n = plan.links;
    let dof = index(plan.dof());
    let space = space(plan);
    let spatial = plan.kind == Kind::Spatial;
    let failure = failure(plan);
    let field = |name: &str, i: usize| {
        let f = id(name, i);
        quote!(self.#f)
    };

    // Sines and cosines of every angle at once (a vectorised kernel), then the links'
    // directions, rates and force pairs.
    // Padded to a multiple of four angles, the kernel's width with AVX2: no scalar tail.
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
    let mut body = quote! {
        let torque = &inputs.torque;
        let pivot = &inputs.pivot_acceleration;
        let g = self.chain.gravity();
        let mut trig = [[0.0f64; 2]; #trig_len];
        #trig_call
    };
    let components: &[&str] = if spatial { &["x", "y", "z"] } else { &["x", "y"] };
    let pivot_names: Vec<Ident> = components.iter().map(|c| format_ident!("pa_{c}")).collect();
    for (k, p) in pivot_names.iter().enumerate() {
        let k = index(k);
        body.extend(quote!(let #p = pivot[#k];));
    }
    for i in 0..n {
        let (st, ct, dth, tau) = (id("st", i), id("ct", i), id("dth", i), id("tau_th", i));
        let ii = index(i);
        let (il, drag) = (field("rod_il", i), field("rod_drag", i));
        let (rate2, pull) = (id("rate2_", i), id("pull_th", i));
        let [ux, uy] = [id("ux", i), id("uy", i)];
        let [fx, fy] = [id("fx", i), id("fy", i)];
        body.extend(quote! {
            let [#st, #ct] = trig[#ii];
            let #dth = qd[#ii];
            let #tau = torque[#ii];
            let #pull = #tau * #il - #drag * #dth;
        });
        if spatial {
            let link = index(i + 1);
            let phi = index(n + i);
            let (sp, cp, dph, tau_ph, is) =
                (id("sp", i), id("cp", i), id("dph", i), id("tau_ph", i), id("is", i));
            let pull_ph = id("pull_ph", i);
            let (etx, ety, uz, fz) = (id("etx", i), id("ety", i), id("uz", i), id("fz", i));
            body.extend(quote! {
                if let Err(error) = ::pendulum_core::check_polar_sin(#link, q[#ii], #st) {
                    return Err(failure(q, qd, inputs, error));
                }
                let [#sp, #cp] = trig[#phi];
                let #dph = qd[#phi];
                let #tau_ph = torque[#phi];
                let #is = 1.0 / #st;
                let #ux = #st * #cp;
                let #uy = #st * #sp;
                let #uz = -#ct;
                let #etx = #ct * #cp;
                let #ety = #ct * #sp;
                let #rate2 = #dth * #dth + #st * #st * #dph * #dph;
                let #pull_ph = #tau_ph * #il * #is - #drag * #st * #dph;
                let #fx = #pull * #etx - #pull_ph * #sp;
                let #fy = #pull * #ety + #pull_ph * #cp;
                let #fz = #pull * #st;
            });
        } else {
            body.extend(quote! {
                let #ux = #st;
                let #uy = -#ct;
                let #rate2 = #dth * #dth;
                let #fx = #pull * #ct;
                let #fy = #pull * #st;
            });
        }
    }

    // Free accelerations a°_i and right-hand sides b_i.
    let u = |c: &str, i: usize| id(&format!("u{c}"), i);
    let f = |c: &str, i: usize| id(&format!("f{c}"), i);
    let free = |c: &str, i: usize| id(&format!("free_{c}"), i);
    for i in 0..n {
        let im = field("rod_im", i);
        let mut dot = Vec::new();
        for (k, c) in components.iter().enumerate() {
            let (a, fi) = (free(c, i), f(c, i));
            let gravity = if k + 1 == components.len() { quote!(-g +) } else { quote!() };
            let pair = if i + 1 < n {
                let below = f(c, i + 1);
                quote!((#fi - #below))
            } else {
                quote!(#fi)
            };
            body.extend(quote!(let #a = #gravity #pair * #im;));
            let above = if i == 0 { pivot_names[k].clone() } else { free(c, i - 1) };
            let ui = u(c, i);
            dot.push(quote!(#ui * (#a - #above)));
        }
        let (b, l, rate2) = (id("b", i), field("rod_l", i), id("rate2_", i));
        body.extend(quote!(let #b = #l * #rate2 #(+ #dot)*;));
    }

    // The elimination by continuants, then the range check and the fallback.
    let mut off_values = Vec::new();
    for i in 0..n {
        let (p, ip, fac, e, h, b, diag) =
            (id("p", i), id("ip", i), id("fac", i), id("e", i), id("h", i), id("b", i), field("rod_diag", i));
        if i == 0 {
            body.extend(quote! {
                let #p = #diag;
                let #ip = 1.0 / #p;
                let #e = #b;
            });
            off_values.push(quote!(0.0));
        } else {
            let off = id("off", i);
            let im_above = field("rod_im", i - 1);
            let products = components.iter().map(|c| {
                let (a, b) = (u(c, i - 1), u(c, i));
                quote!(#a * #b)
            });
            let (p_above, ip_above, e_above) = (id("p", i - 1), id("ip", i - 1), id("e", i - 1));
            // P_{−1} = 1.
            let p_above2 = if i >= 2 {
                let p2 = id("p", i - 2);
                quote!(* #p2)
            } else {
                quote!()
            };
            body.extend(quote! {
                let #off = -(#(#products)+*) * #im_above;
                let #p = #diag * #p_above - (#off * #off) #p_above2;
                let #ip = #p_above / #p;
                let #fac = #off * #ip_above;
                let #e = #b - #fac * #e_above;
            });
            off_values.push(quote!(#off));
        }
        body.extend(quote!(let #h = #e * #ip;));
    }
    let ps: Vec<Ident> = (0..n).map(|i| id("p", i)).collect();
    let facs: Vec<Ident> = (1..n).map(|i| id("fac", i)).collect();
    let hs: Vec<Ident> = (0..n).map(|i| id("h", i)).collect();
    let bs: Vec<Ident> = (0..n).map(|i| id("b", i)).collect();
    let diags: Vec<TokenStream> = (0..n).map(|i| field("rod_diag", i)).collect();
    let fac_index = (1..n).map(index);
    let h_index = (0..n).map(index);
    body.extend(quote! {
        let (low, span) = ::pendulum_core::__private::CONTINUANT_RANGE;
        let out_of_range = false #(| (#ps.to_bits().wrapping_sub(low) > span))*;
        let (#(#facs,)* #(#hs,)*) = if out_of_range {
            let (factor, scaled) = pivots([#(#diags),*], [#(#off_values),*], [#(#bs),*]);
            (#(factor[#fac_index],)* #(scaled[#h_index],)*)
        } else {
            (#(#facs,)* #(#hs,)*)
        };
    });
    let pivots = pivots(n);

    // The up pass: tensions, mass accelerations, link accelerations, angle accelerations.
    for i in (0..n).rev() {
        let (t, h) = (id("t", i), id("h", i));
        if i + 1 == n {
            body.extend(quote!(let #t = #h;));
        } else {
            let (fac_below, t_below) = (id("fac", i + 1), id("t", i + 1));
            body.extend(quote!(let #t = #h - #fac_below * #t_below;));
        }
        let im = field("rod_im", i);
        for c in components {
            let (a, fa, ui) = (id(&format!("a_{c}"), i), free(c, i), u(c, i));
            let pull_below = if i + 1 < n {
                let (t_below, u_below) = (id("t", i + 1), u(c, i + 1));
                quote!(#t_below * #u_below -)
            } else {
                quote!(-)
            };
            body.extend(quote!(let #a = #fa + (#pull_below #t * #ui) * #im;));
        }
    }
    let mut outputs: Vec<TokenStream> = vec![quote!(); plan.dof()];
    for i in 0..n {
        let il = field("rod_il", i);
        let mut udd = Vec::new();
        for (k, c) in components.iter().enumerate() {
            let (a, w) = (id(&format!("a_{c}"), i), id(&format!("udd_{c}"), i));
            let above = if i == 0 { pivot_names[k].clone() } else { id(&format!("a_{c}"), i - 1) };
            body.extend(quote!(let #w = (#a - #above) * #il;));
            udd.push(w);
        }
        let (st, ct) = (id("st", i), id("ct", i));
        let (x_th, ii) = (id("x_th", i), i);
        if spatial {
            let (sp, cp, dth, dph, is, etx, ety) = (
                id("sp", i),
                id("cp", i),
                id("dth", i),
                id("dph", i),
                id("is", i),
                id("etx", i),
                id("ety", i),
            );
            let x_ph = id("x_ph", i);
            let [wx, wy, wz] = [&udd[0], &udd[1], &udd[2]];
            body.extend(quote! {
                let #x_th = #etx * #wx + #ety * #wy + #st * #wz + #dph * #dph * #st * #ct;
                let #x_ph = (#cp * #wy - #sp * #wx - 2.0 * #dth * #dph * #ct) * #is;
            });
            outputs[n + ii] = quote!(#x_ph);
        } else {
            let [wx, wy] = [&udd[0], &udd[1]];
            body.extend(quote!(let #x_th = #ct * #wx + #st * #wy;));
        }
        outputs[ii] = quote!(#x_th);
    }
    let probe = finite_probe(&outputs);
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
            #pivots
            #body
            if #probe != 0.0 {
                return Err(failure(q, qd, inputs, Error::NotPositiveDefinite));
            }
            #(out[#out_index] = #outputs;)*
            Ok(())
        }
    }
}

/// `fn pivots` inside `accelerations`: the elimination by classical pivots
/// `D_i = A_ii − c_i² / D_{i−1}` (a division on the serial chain, but no continuant to
/// leave its range), for the chains whose continuants do: the factors `c_i / D_{i−1}` and
/// the scaled right-hand sides `e_i / D_i`, straight-line like the rest.
fn pivots(n: usize) -> TokenStream {
    let links = index(n);
    let mut body = TokenStream::new();
    for i in 0..n {
        let ii = index(i);
        let (ip, e, s) = (id("ip", i), id("e", i), id("s", i));
        if i == 0 {
            body.extend(quote! {
                let #ip = 1.0 / diagonal[0];
                let #e = rhs[0];
            });
        } else {
            let (fac, ip_above, e_above) = (id("fac", i), id("ip", i - 1), id("e", i - 1));
            body.extend(quote! {
                let #fac = off[#ii] * #ip_above;
                let #ip = 1.0 / (diagonal[#ii] - #fac * off[#ii]);
                let #e = rhs[#ii] - #fac * #e_above;
            });
        }
        body.extend(quote!(let #s = #e * #ip;));
    }
    let facs = (0..n).map(|i| {
        if i == 0 {
            quote!(0.0)
        } else {
            let f = id("fac", i);
            quote!(#f)
        }
    });
    let ss = (0..n).map(|i| id("s", i));
    quote! {
        /// The elimination by classical pivots, for chains whose continuants leave
        /// `CONTINUANT_RANGE`: factors `c_i / D_{i−1}` and scaled right-hand sides `e_i / D_i`.
        #[cold]
        #[inline(never)]
        fn pivots(
            diagonal: [f64; #links],
            off: [f64; #links],
            rhs: [f64; #links],
        ) -> ([f64; #links], [f64; #links]) {
            #body
            ([#(#facs),*], [#(#ss),*])
        }
    }
}
