pendulum_macros::model! {
    pub struct Empty { kind: planar, links: 0 }
}

fn main() {}
