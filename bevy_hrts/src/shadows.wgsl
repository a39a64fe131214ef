// The hrts plugin's `bevy_pbr::shadows`: Bevy's PBR lighting asks this module for each light's shadow, and
// it answers with the plugin's visibility of the light at the fragment's pixel, where Bevy's own module
// sampled a shadow map. bevy_hrts binds the visibility of every light it shadows as the layers of a depth
// array in the place of the directional shadow maps, and tags each light's depth bias with -(layer + 1).
#define_import_path bevy_pbr::shadows

#import bevy_pbr::mesh_view_bindings as view_bindings

// The visibility of the light tagged `tag` at pixel `frag_coord_xy`: 1 for a light the plugin does not shadow.
fn hrts_visibility(tag: f32, frag_coord_xy: vec2<f32>) -> f32 {
    if (tag >= 0.0) {
        return 1.0;
    }
    let layer = i32(round(-tag)) - 1;
    let size = vec2<i32>(textureDimensions(view_bindings::directional_shadow_textures));
    let pixel = clamp(vec2<i32>(floor(frag_coord_xy)), vec2<i32>(0), size - vec2<i32>(1));
    return textureLoad(view_bindings::directional_shadow_textures, pixel, layer, 0);
}

fn fetch_point_shadow(
    light_id: u32,
    frag_position: vec4<f32>,
    surface_normal: vec3<f32>,
    frag_coord_xy: vec2<f32>,
) -> f32 {
    return hrts_visibility(view_bindings::clustered_lights.data[light_id].shadow_depth_bias, frag_coord_xy);
}

fn fetch_spot_shadow(
    light_id: u32,
    frag_position: vec4<f32>,
    surface_normal: vec3<f32>,
    near_z: f32,
    frag_coord_xy: vec2<f32>,
) -> f32 {
    return hrts_visibility(view_bindings::clustered_lights.data[light_id].shadow_depth_bias, frag_coord_xy);
}

fn fetch_directional_shadow(
    light_id: u32,
    frag_position: vec4<f32>,
    surface_normal: vec3<f32>,
    view_z: f32,
    frag_coord_xy: vec2<f32>,
) -> f32 {
    return hrts_visibility(view_bindings::lights.directional_lights[light_id].shadow_depth_bias, frag_coord_xy);
}

// No cascades to show: the plugin's shadows have none.
fn cascade_debug_visualization(output_color: vec3<f32>, light_id: u32, view_z: f32) -> vec3<f32> {
    return output_color;
}

// The first cascade whose far bound lies beyond `view_z` (volumetric fog asks).
fn get_cascade_index(light_id: u32, view_z: f32) -> u32 {
    let light = &view_bindings::lights.directional_lights[light_id];
    var index = 0u;
    while (index + 1u < (*light).num_cascades && -view_z >= (*light).cascades[index].far_bound) {
        index += 1u;
    }
    return index;
}

// Outside every shadow map (w = 0): volumetric fog is not shadowed by the plugin's lights.
fn world_to_directional_light_local(light_id: u32, cascade_index: u32, offset_position: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(0.0);
}
