// G-buffer: depth, and the geometric normal of the visible triangle facing the camera, stored as the
// renderer's conventions say (octahedral or xyz, unorm or float, view or world space).

struct Camera {
    view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    eye: vec4<f32>,
    // Bit 0: octahedral; bit 1: unorm channels; bit 2: view space.
    normal_code: u32,
}

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<mat4x4<f32>>;

struct Varyings {
    @builtin(position) clip: vec4<f32>,
    @location(0) rel: vec3<f32>,
    @location(1) view_z: f32,
}

// The normal target and a linear view-space z (`fs_view_z`, for renderers that keep one).
struct Targets {
    @location(0) normal: vec4<f32>,
    @location(1) view_z: f32,
}

@vertex
fn vs(@location(0) position: vec3<f32>, @builtin(instance_index) instance: u32) -> Varyings {
    let world = instances[instance] * vec4<f32>(position, 1.0);
    return Varyings(camera.view_proj * world, world.xyz - camera.eye.xyz, (camera.view * world).z);
}

fn octahedral(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    return (1.0 - abs(p.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), p >= vec2<f32>(0.0));
}

fn encoded_normal(v: Varyings) -> vec4<f32> {
    var n = normalize(cross(dpdx(v.rel), dpdy(v.rel)));
    if dot(n, v.rel) > 0.0 {
        n = -n;
    }
    if (camera.normal_code & 4u) != 0u {
        n = (camera.view * vec4<f32>(n, 0.0)).xyz;
    }
    var e = vec4<f32>(n, 1.0);
    if (camera.normal_code & 1u) != 0u {
        e = vec4<f32>(octahedral(n), 0.0, 1.0);
    }
    if (camera.normal_code & 2u) != 0u {
        e = vec4<f32>(e.xyz * 0.5 + 0.5, 1.0);
    }
    return e;
}

@fragment
fn fs(v: Varyings) -> @location(0) vec4<f32> {
    return encoded_normal(v);
}

@fragment
fn fs_view_z(v: Varyings) -> Targets {
    return Targets(encoded_normal(v), v.view_z);
}
