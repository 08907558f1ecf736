pendulum_macros::model! {
    pub struct Planar3 { links: 3 }
}

fn main() {}
