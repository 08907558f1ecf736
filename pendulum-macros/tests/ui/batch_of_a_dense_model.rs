//! A dense model (planar, two links: the default) has no batched form; the error says how
//! to get one.
use pendulum_core::batch::UnrolledBatch;
use pendulum_core::Chain;

pendulum_macros::model! { struct Double { kind: planar, links: 2 } }

fn main() {
    let chain = Chain::uniform(2, 0.1, 0.2, 9.81).unwrap();
    let _ = UnrolledBatch::new(vec![Double::new(chain)]);
}
