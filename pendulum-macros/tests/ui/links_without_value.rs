pendulum_macros::model! {
    pub struct Nothing { kind: planar, links: }
}

fn main() {}
