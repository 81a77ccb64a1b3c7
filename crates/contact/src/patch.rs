//! Friction patches: rectangles of the ground `x ∈ [x_min, x_max]`,
//! `z ∈ [z_min, z_max]` (bounds included) with their own Coulomb
//! coefficients (an ice patch, a rubber mat). Where patches overlap the
//! last listed wins; outside every patch the ground's own friction holds.
//! The planar model sees the section `z = 0`.

use crate::mode::Friction;

/// One friction patch (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionPatch {
    /// `[x_min, x_max]` (m).
    pub x: [f64; 2],
    /// `[z_min, z_max]` (m).
    pub z: [f64; 2],
    /// Its coefficients.
    pub friction: Friction,
}

impl FrictionPatch {
    /// `true` when `(x, z)` lies on the patch.
    #[inline]
    pub fn contains(&self, x: f64, z: f64) -> bool {
        self.x[0] <= x && x <= self.x[1] && self.z[0] <= z && z <= self.z[1]
    }
}

/// The friction at `(x, z)`: the last patch of `patches` holding the point,
/// else `base`.
#[inline]
pub fn friction_at(patches: &[FrictionPatch], base: &Friction, x: f64, z: f64) -> Friction {
    patches
        .iter()
        .rev()
        .find(|p| p.contains(x, z))
        .map_or(*base, |p| p.friction)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_last_patch_wins() {
        let f = |s: f64| Friction {
            mu_static: s,
            mu_dynamic: 0.5 * s,
        };
        let p = [
            FrictionPatch {
                x: [0.0, 1.0],
                z: [-1.0, 1.0],
                friction: f(0.1),
            },
            FrictionPatch {
                x: [0.5, 2.0],
                z: [-1.0, 1.0],
                friction: f(0.9),
            },
        ];
        let base = f(0.4);
        assert_eq!(friction_at(&p, &base, -0.1, 0.0), base);
        assert_eq!(friction_at(&p, &base, 0.2, 0.0), f(0.1));
        assert_eq!(friction_at(&p, &base, 0.7, 0.0), f(0.9));
        assert_eq!(friction_at(&p, &base, 0.7, 1.5), base);
    }
}
