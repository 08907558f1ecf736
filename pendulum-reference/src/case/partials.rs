//! The derivatives a case stores (`pendulum-reference/2`): `∂M/∂q` and the Jacobians of
//! the force side `F = Q − c − k − d` by `q`, `q̇`, `p̈` and `σ`, loaded with the case and
//! evaluated, with their scales, at a state.

use anyhow::{Result, anyhow};
use nalgebra::DMatrix;
use serde_json::{Map, Value};

use super::array;
use crate::expr::{Expr, Scaled, Symbols};

/// The stored derivatives of one case, as expressions.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Partials {
    /// `∂M_ab/∂q_x`, `[x][a][b]` flattened.
    mass_matrix: Vec<Expr>,
    /// `∂F_a/∂q_x`, `[a][x]` flattened.
    q: Vec<Expr>,
    /// `∂F_a/∂q̇_x`.
    qd: Vec<Expr>,
    /// `∂F_a/∂p̈_k`.
    pivot: Vec<Expr>,
    /// `∂F_a/∂σ_b`.
    torque: Vec<Expr>,
}

/// The stored derivatives at one state (or their absolute scales).
#[derive(Debug, Clone, PartialEq)]
pub struct PartialsAt {
    /// `∂M/∂q_x`, one dof × dof matrix per coordinate `x`.
    pub mass_matrix: Vec<DMatrix<f64>>,
    /// `∂F/∂q`, dof × dof: entry `(a, x)` is `∂F_a/∂q_x`.
    pub q: DMatrix<f64>,
    /// `∂F/∂q̇`.
    pub qd: DMatrix<f64>,
    /// `∂F/∂p̈`, dof × space.
    pub pivot: DMatrix<f64>,
    /// `∂F/∂σ`, dof × dof.
    pub torque: DMatrix<f64>,
}

impl Partials {
    /// Parses the five keys of `get`, checking every dimension.
    pub(super) fn load(
        root: &Map<String, Value>,
        symbols: &Symbols,
        dof: usize,
        space: usize,
        at: &str,
    ) -> Result<Self> {
        // A nested array of the given dimensions, flattened row-major.
        let nested = |key: &str, dims: &[usize]| -> Result<Vec<Expr>> {
            fn walk(
                v: &Value,
                dims: &[usize],
                symbols: &Symbols,
                at: &str,
                out: &mut Vec<Expr>,
            ) -> Result<()> {
                match dims.split_first() {
                    None => out.push(Expr::parse(v, symbols, at)?),
                    Some((&len, rest)) => {
                        for (i, item) in array(v, len, at)?.iter().enumerate() {
                            walk(item, rest, symbols, &format!("{at}[{i}]"), out)?;
                        }
                    }
                }
                Ok(())
            }
            let mut out = Vec::new();
            let value = root.get(key).ok_or_else(|| anyhow!("{at}: missing key {key:?}"))?;
            walk(value, dims, symbols, &format!("{at}: {key}"), &mut out)?;
            Ok(out)
        };
        Ok(Partials {
            mass_matrix: nested("mass_matrix_partials", &[dof, dof, dof])?,
            q: nested("force_jacobian_q", &[dof, dof])?,
            qd: nested("force_jacobian_qd", &[dof, dof])?,
            pivot: nested("force_jacobian_pivot", &[dof, space])?,
            torque: nested("force_jacobian_torque", &[dof, dof])?,
        })
    }

    /// The values and the absolute scales at the slot values `slots`.
    pub(super) fn evaluate_with_scales(
        &self,
        slots: &[f64],
        dof: usize,
        space: usize,
    ) -> (PartialsAt, PartialsAt) {
        let eval =
            |exprs: &[Expr]| -> Vec<Scaled> { exprs.iter().map(|e| e.eval_with_scale(slots)).collect() };
        let (mass, q, qd, pivot, torque) =
            (eval(&self.mass_matrix), eval(&self.q), eval(&self.qd), eval(&self.pivot), eval(&self.torque));
        let at = |pick: fn(&Scaled) -> f64| {
            let matrix = |v: &[Scaled], cols: usize| {
                DMatrix::from_row_iterator(v.len() / cols, cols, v.iter().map(pick))
            };
            PartialsAt {
                mass_matrix: mass.chunks(dof * dof).map(|c| matrix(c, dof)).collect(),
                q: matrix(&q, dof),
                qd: matrix(&qd, dof),
                pivot: matrix(&pivot, space),
                torque: matrix(&torque, dof),
            }
        };
        (at(|s| s.v), at(|s| s.s))
    }
}
