pendulum_macros::model! {
    pub struct Negative { kind: spatial, links: -3 }
}

fn main() {}
