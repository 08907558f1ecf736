pendulum_macros::model! {
    pub struct Planar12 { kind: planar, links: 12, algorithm: dense, algorithm: tension }
}

fn main() {}
