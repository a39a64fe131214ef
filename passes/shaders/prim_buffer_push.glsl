// Mirrors passes::gpu_types::PrimBufferPush (112 bytes).
struct PrimBufferPush {
    mat4 model;             // object -> world
    uint first_index;       // first index of the draw in the index buffer
    uint triangle_count;    // triangles in the draw
    uint prim_offset;       // draw-call offset: prim buffer slot of the draw's first triangle
    uint vertex_stride;     // in floats
    uint vertex_offset;     // in floats, position of vertex 0
    uint vertex_count;      // vertices addressable by the draw (indices >= this are rejected)
    uint index_16bit;       // 1: indices are packed u16 (little-endian pairs), 0: u32
    int base_vertex;        // added to every index of the draw before it addresses a vertex
    uint vertex_format;     // 0: float3; 1: half4; 2: snorm16x4; 3: unorm16x4 (w ignored)
    uint pad0;
    uint pad1;
    uint pad2;
};
