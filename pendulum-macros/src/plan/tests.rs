//! Tests of `plan`.

use super::*;

fn inputs_of(plan: &Plan, sym: Sym) -> Vec<Sym> {
    plan.full_closure([sym]).into_iter().filter(|s| s.is_input()).collect()
}

#[test]
fn planar_mass_entry_0_2_uses_tail_mass_2_and_angles_0_and_2() {
    let plan = Plan::new(Kind::Planar, 3);
    let entry = plan.mass_entry(0, 2).unwrap();
    assert_eq!(entry, Sym::MassEntry(2, 0));
    assert_eq!(plan.mass_entry(2, 0), Some(entry));
    assert_eq!(plan.definition(entry).unwrap().to_string(), "w0_2*cth0_2");
    assert_eq!(plan.definition(Sym::Weight(0, 2)).unwrap().to_string(), "mt2*l0*l2");
    assert_eq!(plan.definition(Sym::CosDiff(Theta(0), Theta(2))).unwrap().to_string(), "ct0*ct2 + st0*st2");
    assert_eq!(
        inputs_of(&plan, entry),
        [
            Sym::Tail(2),
            Sym::Length(0),
            Sym::Length(2),
            Sym::Trig(Theta(0), Sin),
            Sym::Trig(Theta(0), Cos),
            Sym::Trig(Theta(2), Sin),
            Sym::Trig(Theta(2), Cos),
        ]
    );
}

#[test]
fn planar_diagonal_is_the_weight_alone() {
    let plan = Plan::new(Kind::Planar, 3);
    assert_eq!(plan.definition(Sym::MassEntry(1, 1)).unwrap().to_string(), "w1_1");
    // Stored: a method reads the weight, the constructor computes it.
    assert_eq!(plan.closure([Sym::MassEntry(1, 1)]), [Sym::Weight(1, 1), Sym::MassEntry(1, 1)]);
    assert_eq!(
        plan.full_closure([Sym::MassEntry(1, 1)]),
        [Sym::Tail(1), Sym::Length(1), Sym::Weight(1, 1), Sym::MassEntry(1, 1)]
    );
    assert_eq!(plan.definition(Sym::Weight(1, 1)).unwrap().to_string(), "mt1*l1*l1");
}

#[test]
fn planar_velocity_term_has_one_term_per_other_link_with_the_sign_of_the_difference() {
    let plan = Plan::new(Kind::Planar, 3);
    let c1 = plan.definition(Sym::VelocityTerm(1)).unwrap();
    // sin(θ1 − θ0) = −sin(θ0 − θ1)
    assert_eq!(c1.to_string(), "-w0_1*sth0_1*dth0*dth0 + w1_2*sth1_2*dth2*dth2");
    assert_eq!(plan.per_coordinate(Sym::VelocityTerm), [0, 1, 2].map(|a| Some(Sym::VelocityTerm(a))));
    assert_eq!(Plan::new(Kind::Planar, 1).per_coordinate(Sym::VelocityTerm), [None]);
}

#[test]
fn spatial_zero_entries_are_known() {
    let plan = Plan::new(Kind::Spatial, 2);
    // J_φi·J_θi = 0, gravity has no φ component.
    assert_eq!(plan.mass_entry(2, 0), None);
    assert_eq!(plan.mass_entry(1, 3), None);
    assert!(plan.mass_entry(2, 1).is_some());
    assert_eq!(
        plan.per_coordinate(Sym::GravityTerm),
        [Some(Sym::GravityTerm(0)), Some(Sym::GravityTerm(1)), None, None]
    );
    assert_eq!(plan.definition(Sym::Rhs(3)).unwrap().to_string(), "f3 - c3 - kd3");
    // J_φ has no z component: gravity and the vertical pivot acceleration drop out.
    assert_eq!(plan.definition(Sym::Reach(3)).unwrap().to_string(), "-ax*st1*sp1 + ay*st1*cp1");
    assert_eq!(plan.definition(Sym::Reach(1)).unwrap().to_string(), "ax*ct1*cp1 + ay*ct1*sp1 + lift*st1");
    assert_eq!(plan.definition(Sym::Lift).unwrap().to_string(), "az + g");
}

#[test]
fn spatial_cross_entry_is_minus_sin_theta_cos_theta_sin_phi_difference() {
    let plan = Plan::new(Kind::Spatial, 2);
    // Row φ_1 (index 3), column θ_0: −W_01 sθ1 cθ0 sin(φ1 − φ0) = +W_01 sθ1 cθ0 sin(φ0 − φ1).
    assert_eq!(plan.definition(Sym::MassEntry(3, 0)).unwrap().to_string(), "w0_1*sph0_1*st1*ct0");
    // Row φ_0 (index 2), column θ_1: −W_01 sθ0 cθ1 sin(φ0 − φ1).
    assert_eq!(plan.definition(Sym::MassEntry(2, 1)).unwrap().to_string(), "-w0_1*sph0_1*st0*ct1");
    assert_eq!(plan.definition(Sym::MassEntry(3, 3)).unwrap().to_string(), "w1_1*st1*st1");
}

#[test]
fn every_definition_refers_only_to_earlier_symbols() {
    for plan in (1..=4).flat_map(|n| [Plan::new(Kind::Planar, n), Plan::new(Kind::Spatial, n)]) {
        let roots = (0..plan.dof()).flat_map(|a| (0..=a).map(move |b| Sym::MassEntry(a, b)));
        let roots = roots.chain((0..plan.dof()).map(Sym::Rhs));
        let roots = roots.chain(plan.kinetic_energy().symbols().collect::<Vec<_>>());
        for sym in plan.full_closure(roots) {
            for dep in plan.definition(sym).unwrap_or_default().symbols() {
                assert!(dep < sym, "{plan:?}: {sym} uses {dep}, which sorts after it");
            }
        }
    }
}

#[test]
fn closure_is_sorted_inputs_first_and_mentions_only_what_is_needed() {
    let plan = Plan::new(Kind::Planar, 2);
    let all = plan.closure(plan.potential_energy().symbols().collect::<Vec<_>>());
    let names: Vec<String> = all.iter().map(|s| s.name()).collect();
    assert_eq!(names, ["g", "mt0", "mt1", "l0", "l1", "ct0", "ct1"]);
}

#[test]
fn names_are_distinct() {
    let plan = Plan::new(Kind::Spatial, 12);
    let roots = (0..plan.dof()).flat_map(|a| (0..=a).map(move |b| Sym::MassEntry(a, b)));
    let roots = roots.chain((0..plan.dof()).map(Sym::Rhs));
    let roots = roots.chain(plan.kinetic_energy().symbols().collect::<Vec<_>>());
    let all = plan.closure(roots);
    let names: BTreeSet<String> = all.iter().map(|s| s.name()).collect();
    assert_eq!(names.len(), all.len());
}

#[test]
fn input_symbols_are_exactly_the_first_group() {
    assert!(Sym::Pivot(2).is_input());
    assert!(Sym::Trig(Phi(15), Cos).is_input());
    assert!(!Sym::CosDiff(Theta(0), Theta(1)).is_input());
    assert!(!Sym::Weight(0, 0).is_input());
}
