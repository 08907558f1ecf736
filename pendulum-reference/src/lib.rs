//! The sympy reference of the equations of motion and the claims checker.
//!
//! - [`case`]: a derived case (`reference/cases/*.json`: the mass matrix, forces and
//!   energies of a planar or spatial chain of n links as expression trees, [`expr`]) and
//!   its evaluation at a state; [`embedded`] holds the committed cases, built in.
//! - [`sample`]: the random states every comparison uses (deterministic per seed).
//! - [`claims`]: claims files, equations written by hand in index notation, checked
//!   against the cases at random states, with the common slips diagnosed.
//!
//! `cargo xtask verify` compares the models with the cases; the Python package checks
//! claims files with the embedded cases.

pub mod case;
pub mod claims;
pub mod embedded;
pub mod expr;
pub mod sample;
