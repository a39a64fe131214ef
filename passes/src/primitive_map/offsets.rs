//! The layout of the primitive map's list offsets (`map_offsets.glsl` reads it, `map_pack.comp` writes it):
//! the texels in groups of [`OFFSET_GROUP`] consecutive indices, [`OFFSET_GROUP_WORDS`] `u32` per group.
//! Word 0 is the offset of the group's first list, with [`OFFSET_GROUP_OVERFLOW`] set when a list of the
//! group starts 32768 or more entries after it, or its lists end at 2^31 entries or more (its offsets are
//! not kept: its texels walk the BVH, exact); words 1..=8 hold a 16-bit field per texel (texel `16g + i` in
//! the low half of word `1 + i / 2` for even `i`, the high half for odd `i`): bits 0..=14 the offset of its
//! list from word 0, bit 15 ([`OFFSET_CAPPED`]) set when its list passed the map's list limit and was not
//! kept (it walks the BVH). One more group follows the last, its word 0 the entries of all lists. 2.25 bytes
//! per texel instead of 4.

/// Texels per group of the packed offsets.
pub const OFFSET_GROUP: usize = 16;

/// `u32` words per group: its base, then a 16-bit local offset per texel.
pub const OFFSET_GROUP_WORDS: usize = 1 + OFFSET_GROUP / 2;

/// Bit of a group's base marking local offsets that did not fit 15 bits.
pub const OFFSET_GROUP_OVERFLOW: u32 = 1 << 31;

/// Largest local offset of a texel's list within its group.
pub const OFFSET_LOCAL_MAX: u32 = 0x7FFF;

/// Bit of a texel's 16-bit field marking a list not kept (longer than the map's list limit).
pub const OFFSET_CAPPED: u32 = 0x8000;

/// `u32` words of the packed offsets of `texels` texels (their groups and the final one).
pub fn packed_offset_words(texels: u64) -> u64 {
    (texels.div_ceil(OFFSET_GROUP as u64) + 1) * OFFSET_GROUP_WORDS as u64
}

/// The texels `words` words of packed offsets hold (a multiple of 16: the last group's texels past the
/// map's hold empty lists).
pub fn packed_texels(words: usize) -> usize {
    (words / OFFSET_GROUP_WORDS).saturating_sub(1) * OFFSET_GROUP
}

/// The list offsets unpacked on the host.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ListOffsets {
    /// `texels + 1` offsets: texel t's list is `entries[offsets[t] .. offsets[t + 1]]`, except in an
    /// overflowed group, whose texels all get the group's first offset (and the last the next group's).
    pub offsets: Vec<u32>,
    /// Per texel: its group's local offsets overflowed, so its list's bounds are not kept (its pixels walk
    /// the BVH).
    pub overflowed: Vec<bool>,
    /// Per texel: its list passed the map's list limit and was not kept (its pixels walk the BVH).
    pub capped: Vec<bool>,
}

impl ListOffsets {
    /// The range of texel `t`'s list, if the map kept it (not in an overflowed group, not past the limit).
    pub fn range(&self, t: usize) -> Option<std::ops::Range<usize>> {
        (!*self.overflowed.get(t)? && !self.capped[t])
            .then(|| self.offsets[t] as usize..self.offsets[t + 1] as usize)
    }

    /// Entries of all lists.
    pub fn total(&self) -> u32 {
        self.offsets.last().copied().unwrap_or(0)
    }
}

/// Unpacks the first `texels` texels' list offsets from `packed` (a read-back of the map's offsets).
///
/// # Errors
///
/// `packed` shorter than [`packed_offset_words`] of `texels`.
pub fn unpack_list_offsets(packed: &[u32], texels: usize) -> Result<ListOffsets, String> {
    let groups = texels.div_ceil(OFFSET_GROUP);
    let needed = packed_offset_words(texels as u64) as usize;
    if packed.len() < needed {
        return Err(format!(
            "{} words of packed list offsets hold fewer than {texels} texels ({needed} words)",
            packed.len()
        ));
    }
    let base = |g: usize| packed[g * OFFSET_GROUP_WORDS] & !OFFSET_GROUP_OVERFLOW;
    let mut offsets = Vec::with_capacity(texels + 1);
    let mut overflowed = Vec::with_capacity(texels);
    let mut capped = Vec::with_capacity(texels);
    for t in 0..texels {
        let g = t / OFFSET_GROUP;
        let over = packed[g * OFFSET_GROUP_WORDS] & OFFSET_GROUP_OVERFLOW != 0;
        let word = packed[g * OFFSET_GROUP_WORDS + 1 + (t % OFFSET_GROUP) / 2];
        let field = if t % 2 == 0 {
            word & 0xFFFF
        } else {
            word >> 16
        };
        offsets.push(base(g) + if over { 0 } else { field & OFFSET_LOCAL_MAX });
        overflowed.push(over);
        capped.push(!over && field & OFFSET_CAPPED != 0);
    }
    offsets.push(base(groups));
    Ok(ListOffsets {
        offsets,
        overflowed,
        capped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `map_pack.comp` writes for exclusive offsets `scanned` (texels + 1 values) and the texels
    /// past the list limit `capped`.
    fn pack(scanned: &[u32], capped: &[usize]) -> Vec<u32> {
        let texels = scanned.len() - 1;
        let at = |t: usize| scanned[t.min(texels)];
        let field = |t: usize, base: u32| {
            (at(t) - base)
                | if capped.contains(&t) {
                    OFFSET_CAPPED
                } else {
                    0
                }
        };
        let mut out = vec![0; packed_offset_words(texels as u64) as usize];
        for g in 0..=texels.div_ceil(OFFSET_GROUP) {
            let first = g * OFFSET_GROUP;
            let base = at(first);
            let over = at(first + OFFSET_GROUP - 1) - base > OFFSET_LOCAL_MAX
                || at(first + OFFSET_GROUP) >= OFFSET_GROUP_OVERFLOW;
            out[g * OFFSET_GROUP_WORDS] = base | if over { OFFSET_GROUP_OVERFLOW } else { 0 };
            for i in (0..OFFSET_GROUP).step_by(2) {
                out[g * OFFSET_GROUP_WORDS + 1 + i / 2] = if over {
                    0
                } else {
                    field(first + i, base) | field(first + i + 1, base) << 16
                };
            }
        }
        out
    }

    fn scan(counts: &[u32]) -> Vec<u32> {
        let mut sum = 0;
        let mut out: Vec<u32> = counts
            .iter()
            .map(|&c| {
                sum += c;
                sum - c
            })
            .collect();
        out.push(sum);
        out
    }

    #[test]
    fn packed_offsets_round_trip() {
        for texels in [0, 1, 15, 16, 17, 33, 1000] {
            let counts: Vec<u32> = (0..texels as u32).map(|t| (t * 7919) % 23).collect();
            let scanned = scan(&counts);
            let unpacked = unpack_list_offsets(&pack(&scanned, &[]), texels).unwrap();
            assert_eq!(unpacked.offsets, scanned, "{texels} texels");
            assert!(unpacked.overflowed.iter().all(|&o| !o));
            assert_eq!(unpacked.total(), scanned[texels]);
            for (t, &count) in counts.iter().enumerate() {
                assert_eq!(unpacked.range(t).unwrap().len(), count as usize);
            }
        }
    }

    #[test]
    fn an_overflowed_group_is_reported_and_its_neighbours_kept() {
        let mut counts = vec![3u32; 48];
        counts[20] = 40_000;
        let scanned = scan(&counts);
        let unpacked = unpack_list_offsets(&pack(&scanned, &[]), 48).unwrap();
        for t in 0..48 {
            let in_group = (16..32).contains(&t);
            assert_eq!(unpacked.overflowed[t], in_group, "texel {t}");
            if !in_group {
                assert_eq!(
                    unpacked.range(t),
                    Some(scanned[t] as usize..scanned[t + 1] as usize)
                );
            }
        }
        assert_eq!(unpacked.range(16), None);
        assert_eq!(unpacked.total(), 47 * 3 + 40_000);
    }

    #[test]
    fn lists_ending_past_2_pow_31_mark_their_group() {
        let mut counts = vec![3u32; 48];
        counts[15] = 1 << 31;
        let scanned = scan(&counts);
        let unpacked = unpack_list_offsets(&pack(&scanned, &[]), 48).unwrap();
        // Group 0's last list ends past 2^31, and the bases after it carry the mark's bit.
        assert!(unpacked.overflowed.iter().all(|&o| o));
        assert_eq!(unpacked.range(3), None);
    }

    #[test]
    fn a_group_just_within_15_bits_is_kept() {
        let mut counts = vec![0u32; 16];
        counts[14] = 0x7FFF;
        counts[15] = 1_000_000;
        let scanned = scan(&counts);
        let unpacked = unpack_list_offsets(&pack(&scanned, &[]), 16).unwrap();
        assert!(unpacked.overflowed.iter().all(|&o| !o));
        assert_eq!(unpacked.offsets, scanned);
        counts[14] = 0x8000;
        let scanned = scan(&counts);
        let unpacked = unpack_list_offsets(&pack(&scanned, &[]), 16).unwrap();
        assert!(unpacked.overflowed.iter().all(|&o| o));
    }

    #[test]
    fn texels_past_the_limit_keep_no_list() {
        // The scan read the capped texels' counts as 0.
        let mut counts: Vec<u32> = (0..40).map(|t| t % 5).collect();
        let capped = [3usize, 17, 31];
        for &t in &capped {
            counts[t] = 0;
        }
        let scanned = scan(&counts);
        let unpacked = unpack_list_offsets(&pack(&scanned, &capped), 40).unwrap();
        assert_eq!(unpacked.offsets, scanned);
        for t in 0..40 {
            assert_eq!(unpacked.capped[t], capped.contains(&t), "texel {t}");
            assert_eq!(
                unpacked.range(t).is_none(),
                capped.contains(&t),
                "texel {t}"
            );
        }
    }

    #[test]
    fn short_read_backs_are_refused() {
        assert!(unpack_list_offsets(&[0; 17], 16).is_err());
        assert!(unpack_list_offsets(&[0; 18], 16).is_ok());
        assert_eq!(
            packed_texels(packed_offset_words(1024 * 1024) as usize),
            1024 * 1024
        );
        assert_eq!(packed_texels(packed_offset_words(17) as usize), 32);
        assert_eq!(packed_texels(0), 0);
    }
}
