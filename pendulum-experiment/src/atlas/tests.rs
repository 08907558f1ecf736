//! The atlas's request, grid and chains.

use super::*;
use crate::description::DriveConfig;
use crate::spelling::Front;

fn request() -> AtlasRequest {
    AtlasRequest {
        masses: vec![0.05; 3],
        lengths: vec![0.1; 3],
        gravity: 9.81,
        omega: vec![1.0, 2.0, 3.0],
        scaled: true,
        radius: vec![0.01, 0.02],
        damping: Damping::Uniform(vec![1e-3]),
        ramp_time: vec![],
        kinds: vec![AtlasKind::Sudden, AtlasKind::RampUp, AtlasKind::Sudden],
        duration: Some(30.0),
        step: None,
    }
}

#[test]
fn points_run_kind_by_kind_then_row_by_row() {
    let config = request().resolve().unwrap();
    assert_eq!((config.x.parameter, config.y.parameter), (Parameter::Omega, Parameter::Radius));
    assert_eq!(config.kinds, [AtlasKind::Sudden, AtlasKind::RampUp]);
    assert_eq!((config.len(), config.ramp_time), (12, Some(10.0)));
    let unit = config.reference_speed();
    assert_eq!(config.x.values, [unit, 2.0 * unit, 3.0 * unit]);
    assert_eq!(config.locate(7), (AtlasKind::RampUp, 1, 0));
    let s = config.setting(2, 1);
    assert_eq!((s.omega, s.radius, s.damping), (3.0 * unit, 0.02, vec![1e-3; 3]));
    assert_eq!(
        config.drive(10),
        DriveConfig::RampedCircle { radius: 0.02, initial_omega: 0.0, omega: 2.0 * unit, duration: 10.0 }
    );
}

#[test]
fn bad_requests_say_what_is_wrong() {
    let message = |r: AtlasRequest| r.resolve().unwrap_err().to_string();
    let one_axis = AtlasRequest { radius: vec![0.02], ..request() };
    assert_eq!(
        message(one_axis.clone()),
        "an atlas needs exactly two axes (two of --omega, --radius, --damping, --ramp-time with more than \
         one value), got 1 (--omega)"
    );
    // Python's keyword arguments in the same message.
    assert_eq!(
        one_axis.resolve().unwrap_err().message(Front::Python),
        "an atlas needs exactly two axes (two of omega, radius, damping, ramp_time with more than \
         one value), got 1 (omega)"
    );
    let ramp_axis = AtlasRequest { radius: vec![0.02], ramp_time: vec![1.0, 2.0], ..request() };
    assert!(message(ramp_axis).contains("applies to the kind ramp-up only"));
    let negative = AtlasRequest { radius: vec![0.01, -0.02], ..request() };
    assert_eq!(message(negative), "--radius: -0.02 is not a finite value ≥ 0");
    let zero = message(AtlasRequest { radius: vec![0.0, 0.02], ..request() });
    assert!(zero.starts_with("--radius must be finite and positive"), "{zero}");
    let long_ramp = AtlasRequest { ramp_time: vec![40.0], ..request() };
    let long_ramp = long_ramp.resolve().unwrap_err();
    assert!(long_ramp.to_string().contains("shorter than --duration 30 s"), "{long_ramp}");
    assert!(long_ramp.message(Front::Python).contains("shorter than duration=30 s"), "{long_ramp}");
}

#[test]
fn a_damping_axis_gives_each_column_its_chain() {
    let r = AtlasRequest { radius: vec![0.02], damping: Damping::Uniform(vec![1e-3, 2e-3]), ..request() };
    let atlas = Atlas::new(r.resolve().unwrap()).unwrap();
    assert_eq!(atlas.config().y.parameter, Parameter::Damping);
    assert_eq!(atlas.chain(4).damping().as_slice(), [2e-3; 3]);
    assert_eq!(atlas.chain(1).damping().as_slice(), [1e-3; 3]);
}
