pendulum_macros::model! {
    pub struct Rope { kind: planar, links: 40 }
}

fn main() {}
