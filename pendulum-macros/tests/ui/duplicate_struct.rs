pendulum_macros::model! {
    pub struct Chain3 { kind: planar, links: 3 }
    pub struct Chain3 { kind: spatial, links: 3 }
}

fn main() {}
