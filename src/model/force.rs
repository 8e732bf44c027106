//! Force elements: springs, loads, efforts; and the coordinate-level inputs locks, mimics
//! and initial guesses; with the [`ModelBuilder`] calls that add them.
//!
//! Potentials (`δ` a deflection, `F(δ)` the force law positive in tension):
//! spring `∫₀^{L−L₀} F(δ) dδ`, joint spring `∫₀^{θ−θ_ref} F(δ) dδ`, dead load `−fᵀ r_P`,
//! effort `−τ θ`; a lock is the constraint `θ − value = 0`, a mimic
//! `θ − (m θ_ref + offset) = 0`.

use super::{BodyId, JointId, ModelBuilder};
use nalgebra::Vector3;

/// Which sign of force a spring can carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpringMode {
    /// Tension and compression.
    Both,
    /// Tension only (a cable).
    Tension,
    /// Compression only (a bump stop).
    Compression,
}

/// Force (or torque) as a function of deflection `δ`, positive in tension.
#[derive(Clone, Debug, PartialEq)]
pub enum ForceLaw {
    /// `F = preload + k δ`.
    Linear {
        /// Stiffness \[N/m or N m/rad\].
        stiffness: f64,
        /// Force at zero deflection \[N or N m\].
        preload: f64,
    },
    /// Piecewise-linear table of `(δ, F)` rows, `δ` strictly increasing.
    Table {
        /// `(deflection, force)` rows.
        points: Vec<(f64, f64)>,
        /// Beyond the table: continue the end slopes (`true`) or hold the end forces (`false`).
        extrapolate_linear: bool,
        /// Beyond the table the law is undefined (`extrapolate="error"`).
        bounded: bool,
    },
}

/// One end of a translational spring.
#[derive(Clone, Debug)]
pub struct SpringEnd {
    /// The body (`None` = world).
    pub body: Option<BodyId>,
    /// Attachment point in the body frame (world frame for the world) \[m\].
    pub point: Vector3<f64>,
}

/// Point-to-point translational spring: potential `∫₀^{L−L₀} F(δ) dδ`.
#[derive(Clone, Debug)]
pub struct Spring {
    /// Spring name.
    pub name: String,
    /// The two ends.
    pub ends: [SpringEnd; 2],
    /// Free length `L₀` \[m\].
    pub free_length: f64,
    /// Force law.
    pub law: ForceLaw,
    /// Tension/compression mode.
    pub mode: SpringMode,
}

/// Spring on a joint coordinate: potential `∫₀^{θ−θ_ref} F(δ) dδ`.
#[derive(Clone, Debug)]
pub struct JointSpring {
    /// Joint.
    pub joint: JointId,
    /// Coordinate index of the joint.
    pub dof: usize,
    /// Reference value \[rad or m\].
    pub reference: f64,
    /// Force law.
    pub law: ForceLaw,
}

/// Constant dead force at a body point: potential `−fᵀ r_P`.
#[derive(Clone, Debug)]
pub struct Load {
    /// Load name.
    pub name: String,
    /// The body.
    pub body: BodyId,
    /// Application point in the body frame \[m\].
    pub point: Vector3<f64>,
    /// Force in the world frame \[N\].
    pub force: Vector3<f64>,
}

/// Constant generalized force on a joint coordinate: potential `−τ θ`.
#[derive(Clone, Debug)]
pub struct Effort {
    /// Joint.
    pub joint: JointId,
    /// Coordinate index.
    pub dof: usize,
    /// Torque \[N m\] or force \[N\].
    pub value: f64,
}

/// Held joint coordinate: constraint `θ − value = 0`.
#[derive(Clone, Debug)]
pub struct Lock {
    /// Joint.
    pub joint: JointId,
    /// Coordinate index.
    pub dof: usize,
    /// Held value \[rad or m\]; `None` = the initial-guess value.
    pub value: Option<f64>,
}

/// Linear coupling `θ = multiplier θ_ref + offset`.
#[derive(Clone, Debug)]
pub struct Mimic {
    /// The mimicking joint.
    pub joint: JointId,
    /// The mimicked joint.
    pub reference: JointId,
    /// Multiplier.
    pub multiplier: f64,
    /// Offset \[rad or m\].
    pub offset: f64,
}

/// Initial guess of a joint coordinate.
#[derive(Clone, Debug)]
pub struct Initial {
    /// Joint.
    pub joint: JointId,
    /// Coordinate index.
    pub dof: usize,
    /// Value \[rad or m\].
    pub value: f64,
}

/// A position servo on a single-coordinate joint: a joint spring `τ = −k (θ − θ_ref)` (also
/// in [`crate::Model::joint_springs`]), reported as the actuator torque (or force) that holds
/// the joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Servo {
    /// Joint.
    pub joint: JointId,
    /// Stiffness `k` \[N m/rad or N/m\].
    pub stiffness: f64,
    /// Reference `θ_ref` \[rad or m\].
    pub reference: f64,
}

impl Servo {
    /// The actuator torque (or force) `−k (θ − θ_ref)` at the joint value `theta`.
    pub fn torque(&self, theta: f64) -> f64 {
        -self.stiffness * (theta - self.reference)
    }
}

impl ModelBuilder {
    /// Adds a position servo on coordinate 0 of `joint` (module docs of [`Servo`]): a linear
    /// joint spring of `stiffness` about `reference`, replacing a servo already on the joint.
    pub fn add_servo(&mut self, joint: JointId, stiffness: f64, reference: f64) {
        let law = ForceLaw::Linear {
            stiffness,
            preload: 0.0,
        };
        if let Some(k) = self.model.servos.iter().position(|s| s.joint == joint) {
            self.model.servos.remove(k);
            // Its spring is the k-th servo spring: the servo springs are kept last, in order.
            let first = self.model.joint_springs.len() - self.model.servos.len() - 1;
            self.model.joint_springs.remove(first + k);
        }
        self.model.joint_springs.push(JointSpring {
            joint,
            dof: 0,
            reference,
            law,
        });
        self.model.servos.push(Servo {
            joint,
            stiffness,
            reference,
        });
    }

    /// Adds a point-to-point spring.
    pub fn add_spring(&mut self, spring: Spring) {
        self.model.springs.push(spring);
    }

    /// Adds a spring on coordinate `dof` of `joint`, `reference` \[rad or m\] at zero force.
    pub fn add_joint_spring(&mut self, joint: JointId, dof: usize, law: ForceLaw, reference: f64) {
        self.push_joint_spring(JointSpring {
            joint,
            dof,
            reference,
            law,
        });
    }

    /// Adds a joint spring given in full.
    pub fn push_joint_spring(&mut self, spring: JointSpring) {
        // Before the servos' springs, which are kept last (see `add_servo`).
        let at = self.model.joint_springs.len() - self.model.servos.len();
        self.model.joint_springs.insert(at, spring);
    }

    /// Adds a dead load.
    pub fn add_load(&mut self, load: Load) {
        self.model.loads.push(load);
    }

    /// Adds a constant generalized force on a joint coordinate.
    pub fn add_effort(&mut self, effort: Effort) {
        self.model.efforts.push(effort);
    }

    /// Holds a joint coordinate.
    pub fn add_lock(&mut self, lock: Lock) {
        self.model.locks.push(lock);
    }

    /// Adds a linear coupling between joint coordinates.
    pub fn add_mimic(&mut self, mimic: Mimic) {
        self.model.mimics.push(mimic);
    }

    /// Sets the initial guess of a joint coordinate (the last one given counts). `dof` indexes
    /// the joint's values as in the result (a spherical joint's quaternion `w x y z`, a
    /// floating joint's `x y z w qx qy qz`).
    pub fn add_initial(&mut self, initial: Initial) {
        self.model.initial.push(initial);
    }
}
