//! The closest point of a triangle to a point, and which part of the triangle it lies on
//! (Ericson, Real-Time Collision Detection, 5.1.5: the point's Voronoi region). WGSL twin:
//! `closest_on_triangle` in `shaders/shared/mesh.wgsl`, the same operations in the same order.

use crate::real::{Real, Vec3};

/// The part of a triangle its closest point lies on: [`FACE`], [`EDGE`]` + k` for edge `k`
/// (corners `k` and `(k + 1) % 3`), [`VERTEX`]` + k` for corner `k`.
pub type Region = u32;

/// The closest point is inside the triangle.
pub const FACE: Region = 0;
/// The closest point is on edge `k`: region `EDGE + k`.
pub const EDGE: Region = 1;
/// The closest point is corner `k`: region `VERTEX + k`.
pub const VERTEX: Region = 4;

/// The point of triangle (`a`, `b`, `c`) nearest to `p`, and its [`Region`].
#[inline(always)]
pub fn closest_point<T: Real>(p: Vec3<T>, a: Vec3<T>, b: Vec3<T>, c: Vec3<T>) -> (Vec3<T>, Region) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= T::ZERO && d2 <= T::ZERO {
        return (a, VERTEX);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= T::ZERO && d4 <= d3 {
        return (b, VERTEX + 1);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= T::ZERO && d1 >= T::ZERO && d3 <= T::ZERO {
        return (a + ab * (d1 / (d1 - d3)), EDGE);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= T::ZERO && d5 <= d6 {
        return (c, VERTEX + 2);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= T::ZERO && d2 >= T::ZERO && d6 <= T::ZERO {
        return (a + ac * (d2 / (d2 - d6)), EDGE + 2);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= T::ZERO && d4 - d3 >= T::ZERO && d5 - d6 >= T::ZERO {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, EDGE + 1);
    }
    let denom = T::ONE / (va + vb + vc);
    (a + ab * (vb * denom) + ac * (vc * denom), FACE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3<f64> {
        Vec3::new(x, y, z)
    }

    /// Every region of the unit right triangle in z = 0, against the projection worked by hand.
    #[test]
    fn regions_of_a_right_triangle() {
        let (a, b, c) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0));
        let cases = [
            (v(0.2, 0.2, 1.0), v(0.2, 0.2, 0.0), FACE),
            (v(0.5, -1.0, 1.0), v(0.5, 0.0, 0.0), EDGE),
            (v(1.0, 1.0, -2.0), v(0.5, 0.5, 0.0), EDGE + 1),
            (v(-1.0, 0.3, 0.5), v(0.0, 0.3, 0.0), EDGE + 2),
            (v(-1.0, -1.0, 0.0), a, VERTEX),
            (v(2.0, -0.5, 0.0), b, VERTEX + 1),
            (v(-0.5, 2.0, 0.0), c, VERTEX + 2),
        ];
        for (p, q, region) in cases {
            let (got, r) = closest_point(p, a, b, c);
            assert_eq!(r, region, "{p:?}");
            assert!((got - q).norm() < 1e-15, "{p:?}: {got:?} against {q:?}");
        }
    }
}
