pendulum_macros::model! {
    pub enum Planar3 { kind: planar, links: 3 }
}

fn main() {}
