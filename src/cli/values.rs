//! The library's option enums as command-line values: clap's `ValueEnum` is derived here, in
//! the binary, so that the library does not depend on clap. Each mirror converts both ways
//! by an exhaustive match (a variant added to the library fails to compile here until it is
//! added), and its variants' docs are the help's "Possible values".

use restpose::generate::Family as LibFamily;
use restpose::model::Friction as LibFriction;
use restpose::{
    Limits as LibLimits, LinearAlgebra as LibLinearAlgebra, Method as LibMethod,
    StopSearch as LibStopSearch, Topple as LibTopple,
};

/// A `ValueEnum` mirror of the library enum `$lib` with the same variants.
macro_rules! mirror {
    ($(#[$meta:meta])* $name:ident = $lib:ident { $($(#[$vmeta:meta])* $variant:ident,)* }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
        pub(crate) enum $name {
            $($(#[$vmeta])* $variant,)*
        }

        impl From<$name> for $lib {
            fn from(x: $name) -> Self {
                match x {
                    $($name::$variant => $lib::$variant,)*
                }
            }
        }

        impl From<$lib> for $name {
            fn from(x: $lib) -> Self {
                match x {
                    $($lib::$variant => $name::$variant,)*
                }
            }
        }
    };
}

mirror! {
    /// Minimization method in the independent coordinates (`restpose::Method`).
    Method = LibMethod {
        /// Newton's method with the exact reduced Hessian (modified to be positive definite away
        /// from the minimum) and a backtracking line search.
        Newton,
        /// BFGS quasi-Newton (inverse-Hessian update) with a backtracking line search.
        Bfgs,
        /// Davidon–Fletcher–Powell quasi-Newton, the paper's minimizer.
        Dfp,
    }
}

mirror! {
    /// Linear algebra of the solver (`restpose::LinearAlgebra`).
    LinearAlgebra = LibLinearAlgebra {
        /// Up to 40 bodies (280 coordinates): tree from 3 bodies without closed loops, stops,
        /// contacts, locks or mimics, dense otherwise; above: tree without closed loops, sparse
        /// with them (default).
        Auto,
        /// Dense matrices: full-pivoting partition, dense LU, exact reduced Hessian. `O(N³)`.
        Dense,
        /// Sparse partition, sparse LU (faer), Newton steps from the sparse KKT system. `O(N)` per
        /// iteration for chains, trees and ladders.
        Sparse,
        /// The sparse partition, with `Φ_u` and the KKT system factored body by body along the
        /// kinematic tree (fixed-size blocks, no fill; loops as a small dense border). The sparse
        /// path where a partition does not fit a tree.
        Tree,
    }
}

mirror! {
    /// How a step that reaches joint stops is searched (`restpose::StopSearch`).
    StopSearch = LibStopSearch {
        /// Cut the step where it first reaches a stop: one stop per iteration (default).
        Cut,
        /// Hold each joint at a stop the step reaches while the others move on (the projected
        /// search of bound-constrained Newton methods): every stop reached joins at once; the
        /// step is limited per joint instead of per body.
        Projected,
    }
}

mirror! {
    /// Whether a floating group that cannot stand on its ground start topples first
    /// (`restpose::Topple`).
    Topple = LibTopple {
        /// Turn it as a rigid body over the edges of its support, onto the points it lands
        /// on, until its centre of mass is over its support; then solve (default).
        On,
        /// Solve from the ground start as placed.
        Off,
    }
}

mirror! {
    /// Whether URDF joint limits hold the joints (`restpose::Limits`).
    Limits = LibLimits {
        /// `lower ≤ θ ≤ upper` are inequality constraints: a joint can rest on its stop (default).
        Enforce,
        /// Limits are read and a rest pose outside them is reported, not prevented.
        Ignore,
    }
}

mirror! {
    /// Tangential behaviour of a contact (`restpose::model::Friction`).
    Friction = LibFriction {
        /// Frictionless: the contact pushes along the normal only (the energy minimum).
        None,
        /// A point that touches is held where it first touched (tangential rows added); the
        /// report gives the friction coefficient each contact needs.
        Stick,
    }
}

mirror! {
    /// A generated mechanism family (`restpose::generate::Family`).
    Family = LibFamily {
        /// N-link spatial pendulum chain with joint springs (alternating joint axes).
        Chain,
        /// N-link planar chain (all axes parallel) with joint springs.
        PlanarChain,
        /// Ladder of N closed four-bar loops.
        Ladder,
        /// N-link planar rope hanging from the world onto the ground (sphere contacts).
        Rope,
    }
}
