// Copies one layer of the plugin's visibility (R32Float array) into the same layer of a depth array, the
// texture Bevy's PBR shader reads in the place of its directional shadow maps.

@group(0) @binding(0) var visibility: texture_2d_array<f32>;

struct Varyings {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) layer: u32,
};

@vertex
fn vertex(@builtin(vertex_index) vertex: u32, @builtin(instance_index) layer: u32) -> Varyings {
    // One triangle covering the screen.
    let uv = vec2<f32>(f32((vertex << 1u) & 2u), f32(vertex & 2u));
    return Varyings(vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0), layer);
}

struct Depth {
    @builtin(frag_depth) depth: f32,
};

@fragment
fn fragment(in: Varyings) -> Depth {
    return Depth(textureLoad(visibility, vec2<i32>(floor(in.position.xy)), i32(in.layer), 0).r);
}
