pendulum_macros::model! {
    pub struct Spatial4 { kind: spatial, links: 4, algorithm: }
}

fn main() {}
