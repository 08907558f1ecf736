//! The generated code uses absolute paths only: a module that shadows the prelude, the
//! primitive `f64` and the names the expansion uses still compiles, without warnings.
#![deny(warnings, missing_docs, unreachable_pub, unused_qualifications, unused_results)]

mod shadowed {
    #![allow(non_camel_case_types, dead_code)]

    struct f64;
    struct Ok;
    struct Err;
    struct Some;
    struct Option;
    struct Result;
    struct Vec;
    struct Chain;
    struct Error;
    struct Inputs;
    trait Model {}
    trait From {}
    trait Debug {}
    trait Clone {}
    trait PartialEq {}
    struct SVector;
    struct SMatrix;
    struct Const;
    struct U2;
    struct U3;
    mod nalgebra {}
    mod pendulum_core {}
    mod core {}

    pendulum_macros::model! {
        /// A double pendulum.
        #[allow(dead_code)]
        pub struct Planar2 { kind: planar, links: 2 }
        /// A spherical pendulum.
        pub(crate) struct Spatial1 { kind: spatial, links: 1, }
        /// A planar chain by the rod tensions.
        pub struct Planar5 { kind: planar, links: 5, algorithm: tension }
        /// A spatial chain by the rod tensions.
        pub struct Spatial2 { kind: spatial, links: 2, algorithm: tension }
        /// A larger chain by the mass matrix.
        pub struct Planar9 { algorithm: dense, kind: planar, links: 9 }
    }
}

use pendulum_core::{Chain, Model};

fn main() {
    let chain = Chain::new(&[1.0, 2.0], &[0.5, 0.7], 9.81).unwrap();
    let planar = shadowed::Planar2::new(chain);
    let q = nalgebra::Vector2::new(0.3, -0.2);
    let mut qdd = nalgebra::Vector2::zeros();
    planar.accelerations(&q, &q, &planar.zero_inputs(), &mut qdd).unwrap();
    assert!(qdd.iter().all(|a| a.is_finite()));

    let spatial = shadowed::Spatial1::from(Chain::new(&[1.0], &[1.0], 9.81).unwrap());
    let q = nalgebra::Vector2::new(0.3, 0.0);
    let mut qdd = nalgebra::Vector2::zeros();
    spatial.accelerations(&q, &q, &spatial.zero_inputs(), &mut qdd).unwrap();
    assert!(spatial.energy(&q, &q).is_finite());

    let chain = Chain::uniform(5, 1.0, 0.2, 9.81).unwrap();
    let planar = shadowed::Planar5::new(chain);
    let q = nalgebra::SVector::<f64, 5>::repeat(0.3);
    let mut qdd = nalgebra::SVector::<f64, 5>::zeros();
    planar.accelerations(&q, &q, &planar.zero_inputs(), &mut qdd).unwrap();
    assert!(qdd.iter().all(|a| a.is_finite()));
    let spatial = shadowed::Spatial2::new(Chain::uniform(2, 1.0, 0.5, 9.81).unwrap());
    let q = nalgebra::Vector4::new(0.3, 0.5, 0.0, 1.0);
    let mut qdd = nalgebra::Vector4::zeros();
    spatial.accelerations(&q, &q, &spatial.zero_inputs(), &mut qdd).unwrap();
    assert!(qdd.iter().all(|a| a.is_finite()));
    let dense = shadowed::Planar9::new(Chain::uniform(9, 1.0, 0.1, 9.81).unwrap());
    let q = nalgebra::SVector::<f64, 9>::repeat(0.1);
    let mut qdd = nalgebra::SVector::<f64, 9>::zeros();
    dense.accelerations(&q, &q, &dense.zero_inputs(), &mut qdd).unwrap();
}

pendulum_macros::model! {
    /// Configured out together with its impls.
    #[cfg(any())]
    pub struct Absent { kind: planar, links: 2 }
}
