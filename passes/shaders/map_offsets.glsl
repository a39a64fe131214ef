// The primitive map's list offsets, packed (passes::primitive_map::offsets mirrors it): the texels in groups
// of 16 consecutive indices, 9 words per group: word 0 is the offset of the group's first list (bit 31: a
// list of the group starts 65536 or more entries after it, or its lists end at 2^31 entries or more, so
// the group's offsets are not kept and its texels are traced exhaustively), words 1..8 the 16-bit offset of each texel's list from it (texel 16g + i
// in the low half of word 1 + i/2 for even i, the high half for odd i). A final group's word 0 holds the
// entries of all lists. 2.25 bytes per texel instead of 4. Needs the includer's `offsets[]`.

const uint OFFSET_GROUP = 16u;
const uint OFFSET_GROUP_WORDS = 9u;
const uint OFFSET_GROUP_OVERFLOW = 0x80000000u;

// The 16-bit offset of texel `texel`'s list within its group.
uint local_list_offset(uint texel) {
    uint word = offsets[(texel / OFFSET_GROUP) * OFFSET_GROUP_WORDS + 1u + (texel % OFFSET_GROUP) / 2u];
    return (texel & 1u) == 0u ? word & 0xFFFFu : word >> 16;
}

// Texel `texel`'s list is entries[begin, end); false (and an empty range) when its group overflowed.
bool list_range(uint texel, out uint begin, out uint end) {
    uint base = offsets[(texel / OFFSET_GROUP) * OFFSET_GROUP_WORDS];
    begin = 0u;
    end = 0u;
    if ((base & OFFSET_GROUP_OVERFLOW) != 0u) {
        return false;
    }
    begin = base + local_list_offset(texel);
    end = (texel % OFFSET_GROUP) == OFFSET_GROUP - 1u
        ? offsets[(texel / OFFSET_GROUP + 1u) * OFFSET_GROUP_WORDS] & ~OFFSET_GROUP_OVERFLOW
        : base + local_list_offset(texel + 1u);
    return true;
}
