pendulum_macros::model! {
    pub struct Circle { kind: circular, links: 2 }
}

fn main() {}
