pendulum_macros::model! {
    pub struct Planar<T> { kind: planar, links: 3 }
}

fn main() {}
