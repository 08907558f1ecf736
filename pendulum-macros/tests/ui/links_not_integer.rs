pendulum_macros::model! {
    pub struct Half { kind: planar, links: 2.5 }
}

fn main() {}
