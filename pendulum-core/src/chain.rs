//! Validated chain parameters: masses, lengths, gravity, damping, and the tail masses.

use nalgebra::{DefaultAllocator, Dim, Dyn, OVector, allocator::Allocator};

use crate::error::{Error, Result};

/// The physical parameters of an n-link chain, validated once at construction.
///
/// Link `i` (1-based in the document, index `i - 1` here) is a point mass `m_i` (kg) at
/// the end of a massless rigid rod of length `l_i` (m); link 1 hangs from the pivot.
/// Gravity `g ≥ 0` (m/s²) acts along −y (planar) or −z (spatial). Damping `λ_i ≥ 0`
/// (N·m·s) resists the angular velocity of link `i`'s direction (eq 26:
/// `f_d = σ_d − λ_d θ̇_d`).
///
/// `L` is the number of links as a nalgebra dimension: `Dyn` for the general models,
/// `Const<N>` for generated fixed-N models. A `Chain` that exists is valid: every mass
/// and length is finite and positive, `g` and every damping finite and non-negative.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain<L: Dim = Dyn>
where
    DefaultAllocator: Allocator<L>,
{
    masses: OVector<f64, L>,
    lengths: OVector<f64, L>,
    damping: OVector<f64, L>,
    tail_masses: OVector<f64, L>,
    gravity: f64,
}

impl<L: Dim> Chain<L>
where
    DefaultAllocator: Allocator<L>,
{
    /// A chain with the given masses (kg), lengths (m) and gravity (m/s²), undamped.
    ///
    /// Errors: [`Error::NoLinks`] for empty slices, [`Error::LengthMismatch`] when the
    /// slices differ in length (or differ from `N` for `L = Const<N>`),
    /// [`Error::InvalidMass`], [`Error::InvalidLength`], [`Error::InvalidGravity`].
    pub fn new(masses: &[f64], lengths: &[f64], gravity: f64) -> Result<Self> {
        let n = masses.len();
        if n == 0 {
            return Err(Error::NoLinks);
        }
        if let Some(fixed) = L::try_to_usize()
            && fixed != n
        {
            return Err(Error::LengthMismatch { what: "masses", expected: fixed, got: n });
        }
        if lengths.len() != n {
            return Err(Error::LengthMismatch { what: "lengths", expected: n, got: lengths.len() });
        }
        for (i, &m) in masses.iter().enumerate() {
            if !(m.is_finite() && m > 0.0) {
                return Err(Error::InvalidMass { link: i + 1, value: m });
            }
        }
        for (i, &l) in lengths.iter().enumerate() {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::InvalidLength { link: i + 1, value: l });
            }
        }
        if !(gravity.is_finite() && gravity >= 0.0) {
            return Err(Error::InvalidGravity { value: gravity });
        }
        let dim = L::from_usize(n);
        let masses = OVector::<f64, L>::from_row_slice_generic(dim, nalgebra::U1, masses);
        let lengths = OVector::<f64, L>::from_row_slice_generic(dim, nalgebra::U1, lengths);
        let damping = OVector::<f64, L>::zeros_generic(dim, nalgebra::U1);
        // M_d = Σ_{i ≥ d} m_i (eq 10), summed from the free end.
        let mut tail_masses = masses.clone();
        for i in (0..n.saturating_sub(1)).rev() {
            tail_masses[i] += tail_masses[i + 1];
        }
        Ok(Self { masses, lengths, damping, tail_masses, gravity })
    }

    /// `n` identical links of mass `mass` (kg) and length `length` (m).
    pub fn uniform(n: usize, mass: f64, length: f64, gravity: f64) -> Result<Self> {
        Self::new(&vec![mass; n], &vec![length; n], gravity)
    }

    /// The same chain with damping `λ_i` (N·m·s) on each link.
    ///
    /// Errors: [`Error::LengthMismatch`] when `damping` does not have one entry per link,
    /// [`Error::InvalidDamping`] for a negative or non-finite entry.
    pub fn with_damping(mut self, damping: &[f64]) -> Result<Self> {
        if damping.len() != self.links() {
            return Err(Error::LengthMismatch {
                what: "damping",
                expected: self.links(),
                got: damping.len(),
            });
        }
        for (i, &d) in damping.iter().enumerate() {
            if !(d.is_finite() && d >= 0.0) {
                return Err(Error::InvalidDamping { link: i + 1, value: d });
            }
        }
        self.damping.copy_from_slice(damping);
        Ok(self)
    }

    /// Number of links `n`.
    pub fn links(&self) -> usize {
        self.masses.len()
    }

    /// Number of links as a nalgebra dimension.
    pub fn link_dim(&self) -> L {
        L::from_usize(self.links())
    }

    /// Point masses `m_i`, kg.
    pub fn masses(&self) -> &OVector<f64, L> {
        &self.masses
    }

    /// Rod lengths `l_i`, m.
    pub fn lengths(&self) -> &OVector<f64, L> {
        &self.lengths
    }

    /// Damping coefficients `λ_i`, N·m·s.
    pub fn damping(&self) -> &OVector<f64, L> {
        &self.damping
    }

    /// Tail masses `M_d = Σ_{i ≥ d} m_i` (eq 10), kg: the mass hanging below rod `d`.
    pub fn tail_masses(&self) -> &OVector<f64, L> {
        &self.tail_masses
    }

    /// Gravitational acceleration `g`, m/s².
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    /// The coupling weight `W_ij = M_max(i,j) l_i l_j` (kg·m², 0-based `i`, `j`) that
    /// multiplies every entry of the mass matrix and the velocity terms (eqs 22, 31–39).
    pub fn weight(&self, i: usize, j: usize) -> f64 {
        self.tail_masses[i.max(j)] * self.lengths[i] * self.lengths[j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Const;

    #[test]
    fn tail_masses_sum_from_the_free_end() {
        let c = Chain::<Dyn>::new(&[1.0, 2.0, 3.0], &[1.0, 1.0, 1.0], 9.81).unwrap();
        assert_eq!(c.tail_masses().as_slice(), &[6.0, 5.0, 3.0]);
    }

    #[test]
    fn every_bad_parameter_is_named() {
        type C = Chain<Dyn>;
        assert_eq!(C::new(&[], &[], 1.0), Err(Error::NoLinks));
        assert_eq!(
            C::new(&[1.0, 1.0], &[1.0], 1.0),
            Err(Error::LengthMismatch { what: "lengths", expected: 2, got: 1 })
        );
        assert_eq!(C::new(&[1.0, -2.0], &[1.0, 1.0], 1.0), Err(Error::InvalidMass { link: 2, value: -2.0 }));
        assert_eq!(C::new(&[0.0], &[1.0], 1.0), Err(Error::InvalidMass { link: 1, value: 0.0 }));
        assert!(matches!(C::new(&[f64::NAN], &[1.0], 1.0), Err(Error::InvalidMass { link: 1, .. })));
        assert_eq!(
            C::new(&[1.0], &[f64::INFINITY], 1.0),
            Err(Error::InvalidLength { link: 1, value: f64::INFINITY })
        );
        assert_eq!(C::new(&[1.0], &[1.0], -9.8), Err(Error::InvalidGravity { value: -9.8 }));
        assert!(matches!(C::new(&[1.0], &[1.0], f64::NAN), Err(Error::InvalidGravity { .. })));
        let c = C::new(&[1.0, 1.0], &[1.0, 1.0], 1.0).unwrap();
        assert_eq!(
            c.clone().with_damping(&[0.1]),
            Err(Error::LengthMismatch { what: "damping", expected: 2, got: 1 })
        );
        assert_eq!(c.with_damping(&[0.1, -0.1]), Err(Error::InvalidDamping { link: 2, value: -0.1 }));
    }

    #[test]
    fn fixed_size_chain_checks_its_size() {
        assert_eq!(
            Chain::<Const<3>>::new(&[1.0, 1.0], &[1.0, 1.0], 1.0),
            Err(Error::LengthMismatch { what: "masses", expected: 3, got: 2 })
        );
        assert!(Chain::<Const<2>>::new(&[1.0, 1.0], &[1.0, 1.0], 1.0).is_ok());
    }

    #[test]
    fn messages_name_the_value() {
        let e = Chain::<Dyn>::new(&[1.0, 1.0, -3.5], &[1.0; 3], 9.81).unwrap_err();
        assert_eq!(e.to_string(), "mass of link 3 must be finite and positive, got -3.5");
    }
}
