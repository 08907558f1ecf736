pendulum_macros::model! {}

fn main() {}
