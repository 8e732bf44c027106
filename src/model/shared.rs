//! [`Shared`]: a list of model elements shared between copies of a [`super::Model`] and
//! copied on the first write (`Arc::make_mut`).
//!
//! Load stepping solves with gravity, loads and efforts scaled by `k / n`
//! ([`super::Model::with_load_factor`]): each stage's model shares the bodies, links, joints,
//! collision shapes and contact points with the full one and copies only the lists it
//! changes. Reading a `Shared<T>` is reading a `Vec<T>` (`Deref`), so the crate's code indexes
//! and iterates the model's lists as before.

use std::ops::{Deref, DerefMut};
use std::sync::Arc;

/// A copy-on-write `Vec<T>` (module docs).
#[derive(Clone, PartialEq)]
pub(crate) struct Shared<T>(Arc<Vec<T>>);

impl<T> Default for Shared<T> {
    fn default() -> Self {
        Shared(Arc::new(Vec::new()))
    }
}

impl<T> From<Vec<T>> for Shared<T> {
    fn from(v: Vec<T>) -> Self {
        Shared(Arc::new(v))
    }
}

impl<T> Deref for Shared<T> {
    type Target = Vec<T>;
    fn deref(&self) -> &Vec<T> {
        &self.0
    }
}

impl<T: Clone> DerefMut for Shared<T> {
    /// The list itself, copied first if another model shares it.
    fn deref_mut(&mut self) -> &mut Vec<T> {
        Arc::make_mut(&mut self.0)
    }
}

impl<'a, T> IntoIterator for &'a Shared<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl<'a, T: Clone> IntoIterator for &'a mut Shared<T> {
    type Item = &'a mut T;
    type IntoIter = std::slice::IterMut<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        Arc::make_mut(&mut self.0).iter_mut()
    }
}

impl<T: std::fmt::Debug> std::fmt::Debug for Shared<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A copy shares the list until one side writes; the write leaves the other unchanged.
    #[test]
    fn copies_on_the_first_write() {
        let a: Shared<u32> = vec![1, 2, 3].into();
        let mut b = a.clone();
        assert!(Arc::ptr_eq(&a.0, &b.0));
        b.push(4);
        for x in &mut b {
            *x *= 10;
        }
        assert!(!Arc::ptr_eq(&a.0, &b.0));
        assert_eq!(*a, vec![1, 2, 3]);
        assert_eq!(*b, vec![10, 20, 30, 40]);
        assert_eq!((&a).into_iter().sum::<u32>(), 6);
    }

    /// A load step's model shares the bodies, links and joints with the full one and scales
    /// gravity and loads by the factor, leaving the full model's unchanged.
    #[test]
    fn a_load_step_shares_all_but_the_loads() {
        use crate::model::{Inertial, Load, ModelBuilder};
        use nalgebra::{Isometry3, Matrix3, Vector3};
        let mut b = ModelBuilder::new("one");
        let body = b.add_rigid_body("box", 2.0, Vector3::zeros(), Matrix3::identity());
        b.add_load(Load {
            name: "push".into(),
            body,
            point: Vector3::zeros(),
            force: Vector3::new(1.0, 0.0, 0.0),
        });
        b.add_link(
            "tag",
            Some(body),
            Isometry3::identity(),
            Inertial::massless(),
            Vec::new(),
            Vec::new(),
        );
        let full = b.build().unwrap();
        let half = full.with_load_factor(0.5);
        assert!(Arc::ptr_eq(&full.bodies.0, &half.bodies.0));
        assert!(Arc::ptr_eq(&full.links.0, &half.links.0));
        assert!(Arc::ptr_eq(&full.joints.0, &half.joints.0));
        assert!(!Arc::ptr_eq(&full.loads.0, &half.loads.0));
        assert_eq!(half.loads[0].force.x, 0.5);
        assert_eq!(full.loads[0].force.x, 1.0);
        assert_eq!(half.gravity, full.gravity * 0.5);
    }
}
