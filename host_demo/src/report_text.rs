//! How the demo words what the plugin reports of a light's frame ([`hrts::FrameReport`], [`MapStats`]),
//! shared by `render` and `render --scene`.

use hrts::{FrameReport, MapStats};
use std::collections::BTreeMap;

/// The bytes of each resource the light's passes use, by name: the prim buffer its context's lights share
/// first, then those the plugin allocated for the light.
pub fn resource_bytes(report: &FrameReport) -> impl Iterator<Item = (&'static str, u64)> + '_ {
    let prims = (report.prim_buffer_bytes > 0).then_some(("prim buffer", report.prim_buffer_bytes));
    prims.into_iter().chain(
        report
            .allocated_resources()
            .map(|(resource, bytes)| (resource.name(), bytes)),
    )
}

/// The conservative-raster tier the light's binning used: "none", "tier1", "tier2" or "tier3".
pub fn tier_name(report: &FrameReport) -> &'static str {
    match report.tier {
        0 => "none",
        1 => "tier1",
        2 => "tier2",
        _ => "tier3",
    }
}

/// Where a frame's pixels found their triangles, and what the trace cost (`ms`: GPU ms by pass name):
/// how many walked the BVH rather than a list, and why (no list built this frame: its bin items passed the
/// budget; texels past the list limit or the entry capacity).
pub fn routes_line(st: &MapStats, ms: &BTreeMap<String, f64>) -> String {
    let trace = ms.get("ray trace").copied().unwrap_or(0.0);
    if st.pixels_walked == 0 {
        return format!(
            "every pixel walked its texel's list (trace {trace:.3} ms); {} bin items",
            st.bin_items
        );
    }
    let why = if st.frusta_without_lists > 0 {
        format!(
            "no list built: {} bin items passed the bin budget",
            st.bin_items
        )
    } else {
        format!(
            "{} texels past the list limit, {} past the entry capacity of {} (the lists grow to fit the next \
             frame)",
            st.texels_past_limit, st.texels_past_capacity, st.entry_capacity
        )
    };
    let per_sample = if st.pixels_walked_per_sample > 0 {
        format!(
            ", {} of them each light sample's segment or ray on its own (past the area walk budget)",
            st.pixels_walked_per_sample
        )
    } else {
        String::new()
    };
    format!(
        "{} of {} pixels walked the BVH ({why}){per_sample}; trace {trace:.3} ms in all{}",
        st.pixels_walked,
        st.receiver_pixels,
        if st.walks_unfinished > 0 {
            format!(", {} WALKS UNFINISHED", st.walks_unfinished)
        } else {
            String::new()
        }
    )
}
