// Light-space projection with a rigorous bound on its f32 rounding error, shared by the passes that bin
// triangles and the passes that place ray origins, so that a triangle is binned into every texel that a
// ray crossing it can look up: the acceptance margin of a triangle is the error of its vertices plus the
// largest error of any ray origin (DESIGN §5: no hand-tuned epsilons).

// A dot product of 4 terms in f32 errs by at most 4u/(1-4u) of the sum of the terms' magnitudes
// (u = 2^-24); 16u leaves room for the division and for the error of this bound's own arithmetic.
const float PROJECTION_GAMMA = 16.0 * 5.9604645e-8;

struct Projected {
    vec2 xy;        // projected position (divided by w)
    float depth;    // depth key, increasing away from the light: z (orthographic) or w (perspective)
    float w;
    vec2 xy_err;    // bound on |computed - exact| of xy
    float depth_err;
};

Projected project(mat4 m, vec3 p, bool perspective) {
    precise vec4 c = m * vec4(p, 1.0);
    vec3 ap = abs(p);
    vec4 mag = abs(m[0]) * ap.x + abs(m[1]) * ap.y + abs(m[2]) * ap.z + abs(m[3]);
    vec4 err = PROJECTION_GAMMA * mag;
    Projected r;
    r.w = c.w;
    r.xy = c.xy / c.w;
    float wlo = max(c.w - err.w, 1e-30);
    r.xy_err = (err.xy + abs(r.xy) * err.w) / wlo + abs(r.xy) * (4.0 * 5.9604645e-8);
    r.depth = perspective ? c.w : c.z;
    r.depth_err = perspective ? err.w : err.z;
    return r;
}

// A point in homogeneous texel space (x, y, w of `m`) with a bound on the f32 rounding of each component,
// for triangles that reach the light's plane (map_setup.comp's clipped setup).
struct HPoint {
    vec3 h;
    vec3 err;
};

HPoint project_h(mat4 m, vec3 p) {
    precise vec4 c = m * vec4(p, 1.0);
    vec3 ap = abs(p);
    vec4 mag = abs(m[0]) * ap.x + abs(m[1]) * ap.y + abs(m[2]) * ap.z + abs(m[3]);
    return HPoint(c.xyw, (PROJECTION_GAMMA * mag).xyw);
}
