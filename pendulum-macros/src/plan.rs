//! What to emit for one model, as plain data: every quantity is a named symbol whose
//! definition is a sum of signed products of earlier symbols; no tokens.
//!
//! The formulas are those of `pendulum_core::Planar` and `pendulum_core::Spatial`, with
//! every dot product and angle difference written out in the sines and cosines of single
//! angles:
//!
//! - `cos(a − b) = cos a cos b + sin a sin b`, `sin(a − b) = sin a cos b − cos a sin b`;
//! - spatial, with `J_θi = ∂u_i/∂θ_i`, `J_φi = ∂u_i/∂φ_i` and `Δ = φ_i − φ_j`:
//!   `J_θi·J_θj = cθi cθj cos Δ + sθi sθj`, `J_φi·J_θj = −sθi cθj sin Δ`,
//!   `J_φi·J_φj = sθi sθj cos Δ`, and for the velocity terms
//!   `J_θi·u_j = cθi sθj cos Δ − sθi cθj`, `J_θi·∂²u_j/∂φ_j² = −cθi sθj cos Δ`,
//!   `J_θi·∂²u_j/∂θ_j∂φ_j = cθi cθj sin Δ`, `J_φi·u_j = −sθi sθj sin Δ`,
//!   `J_φi·∂²u_j/∂φ_j² = sθi sθj sin Δ`, `J_φi·∂²u_j/∂θ_j∂φ_j = sθi cθj cos Δ`.
//!
//! Indices are 0-based throughout (link `i` here is link `i + 1` of the document);
//! generalized coordinates are `θ_0 … θ_{n−1}` (planar) or
//! `θ_0 … θ_{n−1}, φ_0 … φ_{n−1}` (spatial), as in `pendulum_core`.

use std::collections::BTreeSet;
use std::fmt;

use self::Angle::{Phi, Theta};
use self::Trig::{Cos, Sin};
pub use self::derivatives::Var;

/// Which chain model to generate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Planar: `q = (θ_1 … θ_n)`, pivot acceleration in (x, y).
    Planar,
    /// Spatial: `q = (θ_1 … θ_n, φ_1 … φ_n)`, pivot acceleration in (x, y, z).
    Spatial,
}

/// How `accelerations` solves for `q̈`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Algorithm {
    /// `M q̈ = Q − c − (k + d)` by an unrolled `L D Lᵀ` factorisation of the mass matrix:
    /// O(n³), fastest for the smallest chains.
    Dense,
    /// The rod tensions' symmetric tridiagonal system, unrolled (the O(n) route of
    /// `pendulum_core::PlanarTension` and `Directions`, in the model's angles).
    Tension,
}

impl Algorithm {
    /// The smallest `n` from which [`Algorithm::Tension`] is the default, per kind: the
    /// crossover measured by `cargo xtask bench` (`docs/bench.md`, "Crossover").
    pub const fn crossover(kind: Kind) -> usize {
        match kind {
            Kind::Planar => 4,
            Kind::Spatial => 2,
        }
    }

    /// The faster algorithm for `links` links of `kind`: dense below the crossover.
    pub const fn default_for(kind: Kind, links: usize) -> Self {
        if links >= Self::crossover(kind) { Algorithm::Tension } else { Algorithm::Dense }
    }
}

/// An angle of the chain: the polar angle θ or the azimuth φ of link `i` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Angle {
    /// `θ_i`.
    Theta(usize),
    /// `φ_i` (spatial only).
    Phi(usize),
}

impl Angle {
    fn link(self) -> usize {
        match self {
            Angle::Theta(i) | Angle::Phi(i) => i,
        }
    }

    /// The same kind of angle on another link.
    fn with_link(self, j: usize) -> Angle {
        match self {
            Angle::Theta(_) => Angle::Theta(j),
            Angle::Phi(_) => Angle::Phi(j),
        }
    }

    fn tag(self) -> &'static str {
        match self {
            Angle::Theta(_) => "th",
            Angle::Phi(_) => "ph",
        }
    }
}

/// Sine or cosine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Trig {
    /// `sin`.
    Sin,
    /// `cos`.
    Cos,
}

/// A named quantity of the generated code: one `let` statement each.
///
/// The variant order is the dependency order: a definition only refers to symbols that
/// sort before it, so emitting a set of symbols sorted is a valid statement order (and a
/// deterministic one). The first group are inputs read from the chain or the arguments;
/// the rest have a [`Plan::definition`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Sym {
    /// `g`, m/s².
    Gravity,
    /// Point mass `m_i`, kg.
    Mass(usize),
    /// Tail mass `M_i = Σ_{k ≥ i} m_k`, kg.
    Tail(usize),
    /// Length `l_i`, m.
    Length(usize),
    /// Damping `λ_i`, N·m·s.
    Damping(usize),
    /// Sine or cosine of one angle, from `q`.
    Trig(Angle, Trig),
    /// The rate of one angle, from `q̇`.
    Rate(Angle),
    /// The torque conjugate to one angle.
    Torque(Angle),
    /// Pivot acceleration component (0 = x, 1 = y, 2 = z), m/s².
    Pivot(usize),
    /// Entry `b` of the vector `v` that `∂(M v)/∂q` is taken at.
    Probe(usize),
    /// `cos(a − b)` for two angles of the same kind, `a` on the lower link.
    CosDiff(Angle, Angle),
    /// `sin(a − b)` for two angles of the same kind, `a` on the lower link.
    SinDiff(Angle, Angle),
    /// The vertical component of `p̈ + g ẑ` (y planar, z spatial), m/s²: the pivot
    /// acceleration and gravity act on the chain together, as `p̈ − g` with `g = −g ẑ`.
    Lift,
    /// `J_a·(p̈ + g ẑ)` for coordinate `a`, m/s².
    Reach(usize),
    /// `W_ij = M_max(i,j) l_i l_j` with `i ≤ j`, kg·m². Stored in the model at
    /// construction ([`Sym::is_stored`]).
    Weight(usize, usize),
    /// `M_i l_i`, kg·m, the moment of the tail masses on link `i`. Stored in the model at
    /// construction.
    Moment(usize),
    /// Component `axis` of the velocity of mass `k` relative to the pivot, m/s.
    Velocity(usize, usize),
    /// Mass-matrix entry `M_rc` with `r ≥ c` (generalized-coordinate indices).
    MassEntry(usize, usize),
    /// Velocity term `c_a`.
    VelocityTerm(usize),
    /// Gravity term `k_a`.
    GravityTerm(usize),
    /// Pivot term `d_a`.
    PivotTerm(usize),
    /// Gravity and pivot terms together, `k_a + d_a = M_i l_i J_a·(p̈ + g ẑ)` (`a` on link `i`).
    Load(usize),
    /// Generalized force `Q_a`.
    Force(usize),
    /// Right-hand side `Q_a − c_a − (k_a + d_a)` of `M q̈ = …`.
    Rhs(usize),
    /// `∂M_rc/∂q_x` with `r ≥ c`.
    MassPartial(usize, usize, usize),
    /// `∂F_a/∂var` of the right-hand side `F_a` ([`Sym::Rhs`]).
    RhsPartial(usize, Var),
}

impl Sym {
    /// Whether the symbol is read from the chain or an argument rather than computed.
    pub fn is_input(self) -> bool {
        self < Sym::CosDiff(Angle::Theta(0), Angle::Theta(0))
    }

    /// Whether the symbol depends on the chain's parameters alone: computed once by the
    /// constructor, stored in the model and read by the methods.
    pub fn is_stored(self) -> bool {
        matches!(self, Sym::Weight(..) | Sym::Moment(_))
    }

    /// The symbol's variable name in the generated code.
    ///
    /// Links are 0-based; `st0`/`ct0` are sin/cos of θ_0, `sp0`/`cp0` of φ_0, `cth0_2` is
    /// `cos(θ_0 − θ_2)`, `sph1_3` is `sin(φ_1 − φ_3)`, `w0_2` is `W_02`, `a2_0` is the
    /// mass-matrix entry (2, 0), `c`, `k`, `d`, `f`, `r` the velocity, gravity and pivot
    /// terms, the forces and the right-hand side by coordinate index.
    pub fn name(self) -> String {
        match self {
            Sym::Gravity => "g".into(),
            Sym::Mass(i) => format!("m{i}"),
            Sym::Tail(i) => format!("mt{i}"),
            Sym::Length(i) => format!("l{i}"),
            Sym::Damping(i) => format!("lam{i}"),
            Sym::Trig(a, t) => {
                let f = match t {
                    Trig::Sin => 's',
                    Trig::Cos => 'c',
                };
                let x = match a {
                    Angle::Theta(_) => 't',
                    Angle::Phi(_) => 'p',
                };
                format!("{f}{x}{}", a.link())
            }
            Sym::Rate(a) => format!("d{}{}", a.tag(), a.link()),
            Sym::Torque(a) => format!("tau_{}{}", a.tag(), a.link()),
            Sym::Pivot(axis) => ["ax", "ay", "az"][axis].into(),
            Sym::CosDiff(a, b) => format!("c{}{}_{}", a.tag(), a.link(), b.link()),
            Sym::SinDiff(a, b) => format!("s{}{}_{}", a.tag(), a.link(), b.link()),
            Sym::Lift => "lift".into(),
            Sym::Reach(a) => format!("p{a}"),
            Sym::Weight(i, j) => format!("w{i}_{j}"),
            Sym::Moment(i) => format!("ml{i}"),
            Sym::Velocity(k, axis) => format!("v{}{k}", ['x', 'y', 'z'][axis]),
            Sym::MassEntry(r, c) => format!("a{r}_{c}"),
            Sym::VelocityTerm(a) => format!("c{a}"),
            Sym::GravityTerm(a) => format!("k{a}"),
            Sym::PivotTerm(a) => format!("d{a}"),
            Sym::Load(a) => format!("kd{a}"),
            Sym::Force(a) => format!("f{a}"),
            Sym::Rhs(a) => format!("r{a}"),
            Sym::Probe(b) => format!("pv{b}"),
            Sym::MassPartial(r, c, x) => format!("dm{r}_{c}_{x}"),
            Sym::RhsPartial(a, var) => format!("dr{a}_{}", var.tag()),
        }
    }
}

impl fmt::Display for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// `coef · Π factors`.
#[derive(Debug, Clone, PartialEq)]
pub struct Term {
    /// A small constant: ±1, ±2 or ½.
    pub coef: f64,
    /// The symbols multiplied, in order; a symbol may repeat (a square).
    pub factors: Vec<Sym>,
}

/// A sum of terms; the empty sum is zero.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Expr {
    /// The terms, added in order.
    pub terms: Vec<Term>,
}

impl Expr {
    /// The expression that is just `sym`.
    pub fn of(sym: Sym) -> Self {
        let mut e = Expr::default();
        e.add(1.0, &[sym]);
        e
    }

    /// Appends `coef · Π factors`.
    fn add(&mut self, coef: f64, factors: &[Sym]) -> &mut Self {
        self.terms.push(Term { coef, factors: factors.to_vec() });
        self
    }

    /// Appends each term of `e` multiplied as `before · term · after`.
    fn add_product(&mut self, before: &[Sym], e: &Expr, after: &[Sym]) -> &mut Self {
        for t in &e.terms {
            let factors: Vec<Sym> = [before, &t.factors, after].concat();
            self.add(t.coef, &factors);
        }
        self
    }

    /// Appends `coef · Π factors` with `signed`, a factor with a sign of its own, second.
    fn add_signed(&mut self, coef: f64, signed: (f64, Sym), factors: &[Sym]) -> &mut Self {
        let mut all = factors.to_vec();
        all.insert(1.min(all.len()), signed.1);
        self.add(coef * signed.0, &all)
    }

    /// Whether this is the empty sum.
    pub fn is_zero(&self) -> bool {
        self.terms.is_empty()
    }

    /// Every symbol the expression mentions.
    pub fn symbols(&self) -> impl Iterator<Item = Sym> + '_ {
        self.terms.iter().flat_map(|t| t.factors.iter().copied())
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.terms.is_empty() {
            return f.write_str("0");
        }
        for (k, t) in self.terms.iter().enumerate() {
            let sign = if t.coef < 0.0 { "-" } else { "+" };
            match (k, sign) {
                (0, "+") => {}
                (0, _) => f.write_str("-")?,
                _ => write!(f, " {sign} ")?,
            }
            let mut parts: Vec<String> = Vec::new();
            if t.coef.abs() != 1.0 {
                parts.push(format!("{}", t.coef.abs()));
            }
            parts.extend(t.factors.iter().map(|s| s.name()));
            f.write_str(&parts.join("*"))?;
        }
        Ok(())
    }
}

/// What to emit for one model: its kind and number of links, and the definition of every
/// symbol and method output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plan {
    /// Planar or spatial.
    pub kind: Kind,
    /// Number of links `n`.
    pub links: usize,
}

fn sin(a: Angle) -> Sym {
    Sym::Trig(a, Sin)
}

fn cos(a: Angle) -> Sym {
    Sym::Trig(a, Cos)
}

/// `cos(a − b)` as a symbol (`cos` is even, so the order of the links does not matter).
fn cos_diff(a: Angle, b: Angle) -> Sym {
    if a.link() <= b.link() { Sym::CosDiff(a, b) } else { Sym::CosDiff(b, a) }
}

/// `sin(a − b)` as a sign and a symbol (`sin(b − a) = −sin(a − b)`).
fn sin_diff(a: Angle, b: Angle) -> (f64, Sym) {
    if a.link() <= b.link() { (1.0, Sym::SinDiff(a, b)) } else { (-1.0, Sym::SinDiff(b, a)) }
}

fn weight(i: usize, j: usize) -> Sym {
    Sym::Weight(i.min(j), i.max(j))
}

impl Plan {
    /// The plan for `links` links of `kind`.
    pub fn new(kind: Kind, links: usize) -> Self {
        Self { kind, links }
    }

    /// Number of generalized coordinates: `n` planar, `2n` spatial.
    pub fn dof(&self) -> usize {
        match self.kind {
            Kind::Planar => self.links,
            Kind::Spatial => 2 * self.links,
        }
    }

    /// Number of pivot-acceleration components: 2 planar, 3 spatial.
    pub fn space(&self) -> usize {
        match self.kind {
            Kind::Planar => 2,
            Kind::Spatial => 3,
        }
    }

    /// The angle that is generalized coordinate `a`.
    pub fn angle(&self, a: usize) -> Angle {
        if a < self.links { Theta(a) } else { Phi(a - self.links) }
    }

    /// The index of `angle` in `q`.
    pub fn index(&self, angle: Angle) -> usize {
        match angle {
            Theta(i) => i,
            Phi(i) => self.links + i,
        }
    }

    /// The definition of a computed symbol; `None` for inputs.
    pub fn definition(&self, sym: Sym) -> Option<Expr> {
        let mut e = Expr::default();
        match sym {
            _ if sym.is_input() => return None,
            Sym::CosDiff(a, b) => {
                e.add(1.0, &[cos(a), cos(b)]).add(1.0, &[sin(a), sin(b)]);
            }
            Sym::SinDiff(a, b) => {
                e.add(1.0, &[sin(a), cos(b)]).add(-1.0, &[cos(a), sin(b)]);
            }
            Sym::Lift => {
                e.add(1.0, &[Sym::Pivot(self.space() - 1)]).add(1.0, &[Sym::Gravity]);
            }
            Sym::Reach(a) => {
                let angle = self.angle(a);
                for axis in 0..self.space() {
                    let p = if axis + 1 == self.space() { Sym::Lift } else { Sym::Pivot(axis) };
                    e.add_product(&[p], &self.jacobian(angle, axis), &[]);
                }
            }
            Sym::Weight(i, j) => {
                e.add(1.0, &[Sym::Tail(j), Sym::Length(i), Sym::Length(j)]);
            }
            Sym::Moment(i) => {
                e.add(1.0, &[Sym::Tail(i), Sym::Length(i)]);
            }
            Sym::Load(a) => {
                e.add(1.0, &[Sym::Moment(self.angle(a).link()), Sym::Reach(a)]);
            }
            // v_k = v_{k−1} + l_k u̇_k, u̇_k = Σ_a J_a q̇_a over link k's angles.
            Sym::Velocity(k, axis) => {
                if k > 0 {
                    e.add(1.0, &[Sym::Velocity(k - 1, axis)]);
                }
                for angle in self.link_angles(k) {
                    e.add_product(&[Sym::Length(k)], &self.jacobian(angle, axis), &[Sym::Rate(angle)]);
                }
            }
            Sym::MassEntry(r, c) => self.mass_entry_expr(r, c, &mut e),
            Sym::VelocityTerm(a) => self.velocity_term_expr(a, &mut e),
            Sym::GravityTerm(a) => {
                if let Theta(i) = self.angle(a) {
                    e.add(1.0, &[Sym::Moment(i), Sym::Gravity, sin(Theta(i))]);
                }
            }
            // d_a = M_i l_i J_a·p̈ (`a` on link `i`); planar d_i = M_i l_i (p̈_x cθ + p̈_y sθ).
            Sym::PivotTerm(a) => {
                let angle = self.angle(a);
                let i = angle.link();
                for axis in 0..self.space() {
                    let before = [Sym::Moment(i), Sym::Pivot(axis)];
                    e.add_product(&before, &self.jacobian(angle, axis), &[]);
                }
            }
            Sym::Force(a) => {
                let angle = self.angle(a);
                let i = angle.link();
                e.add(1.0, &[Sym::Torque(angle)]);
                match angle {
                    // Q_θi = σ_θi − λ_i θ̇_i
                    Theta(_) => e.add(-1.0, &[Sym::Damping(i), Sym::Rate(angle)]),
                    // Q_φi = σ_φi − λ_i sin²θ_i φ̇_i
                    Phi(_) => e.add(-1.0, &[Sym::Damping(i), sin(Theta(i)), sin(Theta(i)), Sym::Rate(angle)]),
                };
            }
            Sym::Rhs(a) => {
                e.add(1.0, &[Sym::Force(a)]);
                for term in [Sym::VelocityTerm(a), Sym::Load(a)] {
                    if !self.is_zero(term) {
                        e.add(-1.0, &[term]);
                    }
                }
            }
            Sym::MassPartial(r, c, x) => return Some(self.mass_partial_expr(r, c, x)),
            Sym::RhsPartial(a, var) => return Some(self.rhs_partial_expr(a, var)),
            _ => unreachable!("{sym:?} is an input"),
        }
        Some(e)
    }

    /// Whether a computed symbol is identically zero (it is then never emitted).
    pub fn is_zero(&self, sym: Sym) -> bool {
        self.definition(sym).is_some_and(|e| e.is_zero())
    }

    /// `M_rc` (`r ≥ c`), symmetric: `M_ab = W_ij J_a·J_b` with `a` on link `i`, `b` on `j`
    /// (`i ≥ j` in the θθ and φφ blocks, whose products are written lower link first).
    fn mass_entry_expr(&self, r: usize, c: usize, e: &mut Expr) {
        let (a, b) = (self.angle(r), self.angle(c));
        let (i, j) = (a.link(), b.link());
        let w = weight(i, j);
        match (self.kind, a, b) {
            // |J_θi|² = 1, planar and spatial (planar angles are all θ).
            (_, Theta(_), Theta(_)) if i == j => e.add(1.0, &[w]),
            // C_ij = W_ij cos(θ_i − θ_j) (eq 22)
            (Kind::Planar, ..) => e.add(1.0, &[w, cos_diff(a, b)]),
            // J_θi·J_θj = cθi cθj cos(φ_i − φ_j) + sθi sθj
            (Kind::Spatial, Theta(_), Theta(_)) => e
                .add(1.0, &[w, cos(Theta(j)), cos(Theta(i)), cos_diff(Phi(j), Phi(i))])
                .add(1.0, &[w, sin(Theta(j)), sin(Theta(i))]),
            // J_φi·J_θj = −sθi cθj sin(φ_i − φ_j); zero for i = j
            (Kind::Spatial, Phi(_), Theta(_)) if i == j => e,
            (Kind::Spatial, Phi(_), Theta(_)) => {
                e.add_signed(-1.0, sin_diff(Phi(i), Phi(j)), &[w, sin(Theta(i)), cos(Theta(j))])
            }
            // J_φi·J_φj = sθi sθj cos(φ_i − φ_j)
            (Kind::Spatial, Phi(_), Phi(_)) if i == j => e.add(1.0, &[w, sin(Theta(i)), sin(Theta(i))]),
            (Kind::Spatial, Phi(_), Phi(_)) => {
                e.add(1.0, &[w, sin(Theta(j)), sin(Theta(i)), cos_diff(Phi(j), Phi(i))])
            }
            (Kind::Spatial, Theta(_), Phi(_)) => unreachable!("M_rc is only asked for r ≥ c"),
        };
    }

    /// `c_a = Σ_j W_ij J_a·ü_j|_{q̈=0}` (`a` on link `i`); planar `Σ_j W_ij sin(θ_i − θ_j) θ̇_j²`.
    fn velocity_term_expr(&self, a: usize, e: &mut Expr) {
        let angle = self.angle(a);
        let i = angle.link();
        let (sti, cti) = (sin(Theta(i)), cos(Theta(i)));
        for j in 0..self.links {
            let w = weight(i, j);
            let (stj, ctj) = (sin(Theta(j)), cos(Theta(j)));
            let (dth, dph) = (Sym::Rate(Theta(j)), Sym::Rate(Phi(j)));
            match (self.kind, angle) {
                (Kind::Planar, _) if i == j => {}
                (Kind::Planar, _) => {
                    e.add_signed(1.0, sin_diff(angle, angle.with_link(j)), &[w, dth, dth]);
                }
                // The j = i term: sθ cθ θ̇² − cθ sθ (θ̇² + φ̇²) = −sθ cθ φ̇².
                (Kind::Spatial, Theta(_)) if i == j => {
                    e.add(-1.0, &[w, sti, cti, dph, dph]);
                }
                // W_ij [sθi cθj θ̇j² − cθi sθj cos Δ (θ̇j² + φ̇j²) + 2 cθi cθj sin Δ θ̇j φ̇j]
                (Kind::Spatial, Theta(_)) => {
                    let cd = cos_diff(Phi(i), Phi(j));
                    let sd = sin_diff(Phi(i), Phi(j));
                    e.add(1.0, &[w, sti, ctj, dth, dth])
                        .add(-1.0, &[w, cti, stj, cd, dth, dth])
                        .add(-1.0, &[w, cti, stj, cd, dph, dph])
                        .add_signed(2.0, sd, &[w, cti, ctj, dth, dph]);
                }
                // The j = i term: 2 sθ cθ θ̇ φ̇.
                (Kind::Spatial, Phi(_)) if i == j => {
                    e.add(2.0, &[w, sti, cti, dth, dph]);
                }
                // W_ij [sθi sθj sin Δ (θ̇j² + φ̇j²) + 2 sθi cθj cos Δ θ̇j φ̇j]
                (Kind::Spatial, Phi(_)) => {
                    let cd = cos_diff(Phi(i), Phi(j));
                    let sd = sin_diff(Phi(i), Phi(j));
                    e.add_signed(1.0, sd, &[w, sti, stj, dth, dth])
                        .add_signed(1.0, sd, &[w, sti, stj, dph, dph])
                        .add(2.0, &[w, sti, ctj, cd, dth, dph]);
                }
            }
        }
    }

    /// The angles of link `k`: `θ_k`, and `φ_k` when spatial.
    fn link_angles(&self, k: usize) -> Vec<Angle> {
        match self.kind {
            Kind::Planar => vec![Theta(k)],
            Kind::Spatial => vec![Theta(k), Phi(k)],
        }
    }

    /// Component `axis` of `J_a = ∂u_i/∂a`, the link direction's derivative by one of its
    /// angles (empty where zero): planar `u = (sθ, −cθ)`, `J_θ = (cθ, sθ)`; spatial
    /// `J_θ = (cθ cφ, cθ sφ, sθ)`, `J_φ = (−sθ sφ, sθ cφ, 0)`. One term at most, the
    /// factors in the order above.
    fn jacobian(&self, angle: Angle, axis: usize) -> Expr {
        let i = angle.link();
        let (th, ph) = (Theta(i), Phi(i));
        let mut e = Expr::default();
        match (self.kind, angle, axis) {
            (Kind::Planar, _, 0) => e.add(1.0, &[cos(th)]),
            (Kind::Planar, _, _) => e.add(1.0, &[sin(th)]),
            (Kind::Spatial, Theta(_), 0) => e.add(1.0, &[cos(th), cos(ph)]),
            (Kind::Spatial, Theta(_), 1) => e.add(1.0, &[cos(th), sin(ph)]),
            (Kind::Spatial, Theta(_), _) => e.add(1.0, &[sin(th)]),
            (Kind::Spatial, Phi(_), 0) => e.add(-1.0, &[sin(th), sin(ph)]),
            (Kind::Spatial, Phi(_), 1) => e.add(1.0, &[sin(th), cos(ph)]),
            (Kind::Spatial, Phi(_), _) => &mut e,
        };
        e
    }

    /// The symbols of the lower triangle of `M` (`r ≥ c`) that are not identically zero,
    /// row by row: the mass-matrix entries a method computes.
    pub fn mass_entries(&self) -> Vec<Sym> {
        (0..self.dof()).flat_map(|r| (0..=r).filter_map(move |c| self.mass_entry(r, c))).collect()
    }

    /// The symbol of `M_rc` (either triangle), `None` where the entry is identically zero.
    pub fn mass_entry(&self, r: usize, c: usize) -> Option<Sym> {
        let sym = Sym::MassEntry(r.max(c), r.min(c));
        (!self.is_zero(sym)).then_some(sym)
    }

    /// Kinetic energy `T = ½ Σ_k m_k |v_k|²`, `v_k = Σ_{j ≤ k} l_j u̇_j`.
    pub fn kinetic_energy(&self) -> Expr {
        let mut e = Expr::default();
        for k in 0..self.links {
            for axis in 0..self.space() {
                let v = Sym::Velocity(k, axis);
                e.add(0.5, &[Sym::Mass(k), v, v]);
            }
        }
        e
    }

    /// Potential energy `U = −Σ_i M_i g l_i cos θ_i` (eq 12).
    pub fn potential_energy(&self) -> Expr {
        let mut e = Expr::default();
        for i in 0..self.links {
            e.add(-1.0, &[Sym::Tail(i), Sym::Gravity, Sym::Length(i), cos(Theta(i))]);
        }
        e
    }

    /// One output per coordinate: `sym(a)` or `None` where it is identically zero.
    pub fn per_coordinate(&self, sym: fn(usize) -> Sym) -> Vec<Option<Sym>> {
        (0..self.dof()).map(|a| Some(sym(a)).filter(|&s| !self.is_zero(s))).collect()
    }

    /// Links whose polar angle must be checked for the `sin θ = 0` singularity (1-based,
    /// as `pendulum_core::check_polar_sin` takes them) with the index of θ in `q`.
    pub fn singular_links(&self) -> Vec<(usize, usize)> {
        match self.kind {
            Kind::Planar => Vec::new(),
            Kind::Spatial => (0..self.links).map(|i| (i + 1, i)).collect(),
        }
    }

    /// `roots` and everything they depend on, sorted into a valid statement order, as a
    /// method computes them: [stored](Sym::is_stored) symbols are read, not expanded.
    pub fn closure(&self, roots: impl IntoIterator<Item = Sym>) -> Vec<Sym> {
        self.closure_of(roots, false)
    }

    /// [`Plan::closure`] expanding stored symbols too, down to the chain's parameters:
    /// what the constructor computes.
    pub fn full_closure(&self, roots: impl IntoIterator<Item = Sym>) -> Vec<Sym> {
        self.closure_of(roots, true)
    }

    fn closure_of(&self, roots: impl IntoIterator<Item = Sym>, expand_stored: bool) -> Vec<Sym> {
        let mut done = BTreeSet::new();
        let mut todo: Vec<Sym> = roots.into_iter().collect();
        while let Some(sym) = todo.pop() {
            if done.insert(sym)
                && (expand_stored || !sym.is_stored())
                && let Some(def) = self.definition(sym)
            {
                todo.extend(def.symbols());
            }
        }
        done.into_iter().collect()
    }
}

mod derivatives;
#[cfg(test)]
mod tests;
