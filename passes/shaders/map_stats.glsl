// Mirrors passes::gpu_types::MapStats (16 bytes).
struct MapStats {
    uint overflowed_texels;
    uint max_count;
    uint occupied_texels;
    uint stored_entries;
};
