//! Energy in the inertial frame: the energy and the powers of drive, torques and damping
//! (`power`), and the ledger that integrates those powers along a run so the balance can
//! be checked ([`Accounted`], one type for chains in angles and in unit directions).

pub(crate) mod ledger;
pub(crate) mod power;

pub use ledger::{Accounted, AccountedDirections, Balance, Ledger, Powered};
pub use power::{Powers, inertial_energy, pivot_force, pivot_momentum, pivot_momentum_rate, powers};
