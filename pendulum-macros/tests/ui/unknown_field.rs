pendulum_macros::model! {
    pub struct Planar3 { kind: planar, links: 3, mass: 1.0 }
}

fn main() {}
