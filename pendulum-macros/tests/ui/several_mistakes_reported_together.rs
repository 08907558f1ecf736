// Every field mistake of every item is reported in one compile.
pendulum_macros::model! {
    pub struct First { kind: circular, links: 40 }
    pub struct Second { kind: planar, mass: 2.0 }
}

fn main() {}
