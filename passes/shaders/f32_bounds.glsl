// Rounding bounds of f32 arithmetic (every operation correctly rounded, products possibly fused into a
// multiply-add; sqrt and division within a few ulps, as Vulkan requires), and a lower bound on a point's
// distance to a triangle built on them.

// Unit roundoff of f32.
const float U = 5.9604645e-8;

// |a| x |b| term by term: bounds |a x b| and the rounding of computing it.
vec3 cross_mag(vec3 a, vec3 b) {
    return vec3(a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x);
}

// A lower bound on the distance from `p` to the triangle (a, b, c), every input taken as exact: the
// larger of the distances to the triangle's bounding box and to its plane, each computed in f32 and
// lowered past every rounding of that computation. It holds for any triangle, slivers included (whose
// f32 normal may point well off the true one: the plane's error bound then grows and the box decides);
// 0 where nothing better is known.
float distance_below(vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 lo = min(min(a, b), c), hi = max(max(a, b), c);
    // The box: each gap is one rounded difference of exact values (relative error U), and length() is
    // within a few ulps (sqrt and division, 2.5 ulps each); where it overflows, the largest gap.
    vec3 gap = max(max(lo - p, p - hi), vec3(0.0));
    float box = length(gap) * (1.0 - 64.0 * U);
    if (isinf(box)) {
        box = max(max(gap.x, gap.y), gap.z) * (1.0 - 2.0 * U);
    }
    // The plane: |det(e0, e1, d)| / |e0 x e1| with e0 = b - a, e1 = c - a, d = p - a. The computed
    // determinant (three rounded differences, the cross product's products and difference, the dot
    // product's products and sums) is within 8.01 U of the sum P of its six terms' magnitudes from the
    // exact one; the computed cross product is within 4.01 U |e0| x |e1| (term by term) of the exact
    // normal. Both bounds are taken with room for their own rounding.
    vec3 e0 = b - a, e1 = c - a, d = p - a;
    vec3 n = cross(e0, e1);
    vec3 n_mag = cross_mag(abs(e0), abs(e1));
    float det_error = 12.0 * U * dot(n_mag, abs(d));
    float numerator = abs(dot(n, d)) - det_error;
    float denominator = (length(n) + 8.0 * U * length(n_mag)) * (1.0 + 64.0 * U);
    float plane = numerator > 0.0 && denominator > 0.0
        ? numerator / denominator * (1.0 - 64.0 * U) : 0.0;
    return max(box, plane);
}
