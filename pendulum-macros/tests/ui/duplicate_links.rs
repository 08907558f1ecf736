pendulum_macros::model! {
    pub struct Planar3 { links: 3, kind: planar, links: 4 }
}

fn main() {}
