// Appends `prim` to the list of the texel under this fragment. The count keeps growing past d so that
// overflow is exact (count > d); indices are only stored while the slot is < d, so nothing is written
// out of bounds.
layout(set = 0, binding = 1, r32ui) uniform coherent uimage2D count_map;
layout(set = 0, binding = 2, r32ui) uniform writeonly uimage2DArray index_map;

void append_primitive(uint prim) {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    uint slot = imageAtomicAdd(count_map, texel, 1u);
    if (slot < pc.depth) {
        imageStore(index_map, ivec3(texel, int(slot)), uvec4(prim));
    }
}
