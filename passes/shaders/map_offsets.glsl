// The primitive map's list offsets, packed (passes::primitive_map::offsets mirrors it): the texels in groups
// of 16 consecutive indices, 9 words per group: word 0 is the offset of the group's first list (bit 31: a
// list of the group starts 32768 or more entries after it, or its lists end at 2^31 entries or more, so
// the group's offsets are not kept and its texels walk the BVH), words 1..8 a 16-bit field per texel (texel
// 16g + i in the low half of word 1 + i/2 for even i, the high half for odd i): bits 0..14 the offset of its
// list from word 0, bit 15 set when its list was longer than the map's list limit and not kept (the texel
// walks the BVH). A final group's word 0 holds the entries of all lists. 2.25 bytes per texel instead of 4.
// Needs the includer's `offsets[]`.

const uint OFFSET_GROUP = 16u;
const uint OFFSET_GROUP_WORDS = 9u;
const uint OFFSET_GROUP_OVERFLOW = 0x80000000u;
const uint OFFSET_LOCAL_MAX = 0x7FFFu;
const uint OFFSET_CAPPED = 0x8000u;

// The 16-bit field of texel `texel` within its group.
uint local_field(uint texel) {
    uint word = offsets[(texel / OFFSET_GROUP) * OFFSET_GROUP_WORDS + 1u + (texel % OFFSET_GROUP) / 2u];
    return (texel & 1u) == 0u ? word & 0xFFFFu : word >> 16;
}

// Texel `texel`'s list is entries[begin, end); false (and an empty range) when its group overflowed or its
// list was not kept.
bool list_range(uint texel, out uint begin, out uint end) {
    uint base = offsets[(texel / OFFSET_GROUP) * OFFSET_GROUP_WORDS];
    begin = 0u;
    end = 0u;
    uint field = local_field(texel);
    if ((base & OFFSET_GROUP_OVERFLOW) != 0u || (field & OFFSET_CAPPED) != 0u) {
        return false;
    }
    begin = base + field;
    end = (texel % OFFSET_GROUP) == OFFSET_GROUP - 1u
        ? offsets[(texel / OFFSET_GROUP + 1u) * OFFSET_GROUP_WORDS] & ~OFFSET_GROUP_OVERFLOW
        : base + (local_field(texel + 1u) & OFFSET_LOCAL_MAX);
    return true;
}
