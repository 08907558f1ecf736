pendulum_macros::model! {
    pub struct Planar3 { kind: planar }
}

fn main() {}
