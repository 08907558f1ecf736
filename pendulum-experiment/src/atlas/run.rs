//! An atlas ready to run ([`Atlas`]: the chain of every row or column) and its points
//! ([`AtlasPoint`]), any set of them run as one batch of chains.

use nalgebra::Dyn;
use pendulum_core::Chain;
use serde::{Deserialize, Serialize};

use super::{AtlasConfig, AtlasKind, Parameter};
use crate::description::DriveConfig;
use crate::error::{Error, Result};
use crate::options::damped;
use crate::points::{Outcome, Status};
use crate::spelling::opt;
use crate::whirls::{WhirlResult, WhirlRuns, WhirlStop};

/// An atlas ready to run: its configuration and the chains of its rows or columns.
#[derive(Debug, Clone)]
pub struct Atlas {
    config: AtlasConfig,
    whirls: WhirlRuns,
    /// The damped chain of every damping value (one if the damping is not an axis).
    chains: Vec<Chain<Dyn>>,
}

impl Atlas {
    /// Checks `config` and builds its chains.
    pub fn new(config: AtlasConfig) -> Result<Self> {
        config.check()?;
        let chain = config.chain()?;
        let damped = |d: &[f64]| damped(&chain, d);
        let chains = match (&config.damping, config.axis(Parameter::Damping)) {
            (Some(d), _) => vec![damped(d)?],
            (None, Some(axis)) => {
                axis.values.iter().map(|&v| damped(&vec![v; config.links()])).collect::<Result<_>>()?
            }
            (None, None) => return Err(Error::invalid(format!("{}: no value given", opt("damping")))),
        };
        let whirls = WhirlRuns::new(
            chains[0].clone(),
            config.duration,
            config.step,
            config.feed_every,
            (config.settle_periods, config.settle_tolerance),
        );
        Ok(Self { config, whirls, chains })
    }

    /// The configuration.
    pub fn config(&self) -> &AtlasConfig {
        &self.config
    }

    /// The damped chain of point `index`.
    pub fn chain(&self, index: usize) -> &Chain<Dyn> {
        let (_, ix, iy) = self.config.locate(index);
        match (self.config.x.parameter, self.config.y.parameter) {
            (Parameter::Damping, _) => &self.chains[ix],
            (_, Parameter::Damping) => &self.chains[iy],
            _ => &self.chains[0],
        }
    }

    /// Runs the points `indices` (each < [`AtlasConfig::len`]) as one batch of chains on
    /// the current rayon pool, bit for bit each point alone; `stop()` is asked at every
    /// sample. Results in the order of `indices`.
    pub fn run(&self, indices: &[usize], stop: &(dyn Fn() -> bool + Sync)) -> Vec<WhirlResult> {
        if let Some(&bad) = indices.iter().find(|&&i| i >= self.config.len()) {
            let why =
                WhirlStop::Failed(format!("point {bad} is not in the atlas of {} points", self.config.len()));
            return indices.iter().map(|_| Err(why.clone())).collect();
        }
        let drives: Vec<DriveConfig> = indices.iter().map(|&i| self.config.drive(i)).collect();
        let whirls: Vec<(&Chain<Dyn>, &DriveConfig)> =
            indices.iter().zip(&drives).map(|(&i, d)| (self.chain(i), d)).collect();
        self.whirls.run_batch_of(&whirls, stop)
    }

    /// The points of the atlas, all pending.
    pub fn points(&self) -> Vec<AtlasPoint> {
        (0..self.config.len()).map(|i| self.point(i)).collect()
    }

    /// Point `index` (< [`AtlasConfig::len`]), pending.
    pub fn point(&self, index: usize) -> AtlasPoint {
        let (kind, ix, iy) = self.config.locate(index);
        AtlasPoint {
            kind,
            x: self.config.x.values[ix],
            y: self.config.y.values[iy],
            status: Status::Pending,
            error: None,
            result: None,
        }
    }
}

/// One point of the atlas: its kind and place, where it stands, and its result once run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasPoint {
    /// How it is started.
    pub kind: AtlasKind,
    /// Its value of the x axis' parameter.
    pub x: f64,
    /// Its value of the y axis' parameter.
    pub y: f64,
    /// Where it stands.
    pub status: Status,
    /// Why it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// What the shape analysis said at the end (no wall time: the file does not depend on
    /// the machine or on how the atlas was cut).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub result: Option<Outcome>,
}

impl AtlasPoint {
    /// Records how the point's run ended.
    pub fn record(&mut self, ended: WhirlResult) {
        match ended {
            Ok(end) => {
                self.status = Status::Completed;
                self.error = None;
                self.result = Some(Outcome::of(&end.report, end.steps, None, end.balance));
            }
            Err(WhirlStop::Interrupted) => self.status = Status::Interrupted,
            Err(WhirlStop::Failed(e)) => {
                self.status = Status::Failed;
                self.error = Some(e);
            }
        }
    }
}
