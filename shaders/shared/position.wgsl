// Compensated positions (src/position.rs): a grain is at pos.xyz + residual.xyz, the residual
// keeping what rounding took off pos; the residual's w is always 0. The same operations in the
// same order as the CPU twin.
//
// WGSL lets a compiler reassociate floating-point operations, and compilers do: lavapipe turns
// (a + b) - a into b, and saw through a product by an opaque 1.0 in a chain of these sums,
// which made every rounding error zero, and regrouped a separation's sum now and then. Each
// intermediate whose rounding matters is therefore passed through keep(): its bits xored with
// a residual's w, a 0 the compiler cannot know, so that no float algebra reaches across it.

fn keep(x: vec3<f32>, zero: f32) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(x) ^ vec3<u32>(bitcast<u32>(zero)));
}

// a + b as its rounded value (.s) and the exact rounding error (.e): Knuth's TwoSum.
struct TwoSum {
    s: vec3<f32>,
    e: vec3<f32>,
}

fn two_sum(a: vec3<f32>, b: vec3<f32>, zero: f32) -> TwoSum {
    let s = keep(a + b, zero);
    let bb = keep(s - a, zero);
    return TwoSum(s, keep(a - keep(s - bb, zero), zero) + keep(b - bb, zero));
}

// The position (p, r.xyz) moved by dx, renormalised (src/position.rs advance).
fn advance(p: vec3<f32>, r: vec4<f32>, dx: vec3<f32>) -> TwoSum {
    let a = two_sum(p, dx, r.w);
    return two_sum(a.s, keep(r.xyz + a.e, r.w), r.w);
}

// A difference of two positions' pos parts completed by their residuals' difference
// (src/position.rs complete).
fn complete(d: vec3<f32>, r: vec3<f32>, zero: f32) -> vec3<f32> {
    return keep(d, zero) + keep(r, zero);
}
