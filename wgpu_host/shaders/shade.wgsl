// Deferred shading: a grey surface lit by the directional light through the plugin's shadow image, and
// a sky where the depth holds nothing.

struct Shade {
    // Direction towards the light, in the space of the stored normals.
    to_light: vec4<f32>,
    normal_code: u32,
    far_depth: f32,
}

@group(0) @binding(0) var<uniform> shade: Shade;
@group(0) @binding(1) var depth: texture_depth_2d;
@group(0) @binding(2) var normals: texture_2d<f32>;
@group(0) @binding(3) var shadow: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn octahedral_decode(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    let t = max(-n.z, 0.0);
    n.x += select(t, -t, n.x >= 0.0);
    n.y += select(t, -t, n.y >= 0.0);
    return normalize(n);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let px = vec2<i32>(p.xy);
    if textureLoad(depth, px, 0) == shade.far_depth {
        return vec4<f32>(0.55, 0.7, 0.9, 1.0);
    }
    var e = textureLoad(normals, px, 0);
    if (shade.normal_code & 2u) != 0u {
        e = e * 2.0 - 1.0;
    }
    var n = normalize(e.xyz);
    if (shade.normal_code & 1u) != 0u {
        n = octahedral_decode(e.xy);
    }
    let lit = textureLoad(shadow, px, 0).r;
    let diffuse = max(dot(n, shade.to_light.xyz), 0.0) * lit;
    let c = vec3<f32>(0.8) * (0.2 + 0.8 * diffuse);
    return vec4<f32>(c, 1.0);
}
