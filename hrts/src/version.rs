//! The versions of the C structs this library reads and writes. A struct's `struct_size`, or the stride of
//! an array of elements without one, says which version the caller was built with: the library reads the
//! fields that version has, gives the newer ones their documented defaults, and writes back only what the
//! caller's struct holds. `HRTS_API_VERSION` documents the rules the versions follow.

use crate::error::{check_aligned, ApiError, ApiResult};
use crate::types::*;
use std::mem::{offset_of, size_of};

/// The oldest minor version of `HRTS_API_VERSION`'s major version this library reads. The 5.0 headers
/// changed struct layouts without changing the version (`HrtsDraw` 72 then 76 bytes, `HrtsTargets` 64, 72
/// then 80), so a 5.0 caller's structs cannot be told apart.
pub(crate) const OLDEST_MINOR: u32 = 1;

/// The major and minor version of an `HRTS_API_VERSION` value.
pub(crate) fn major_minor(version: u32) -> (u32, u32) {
    (version >> 22, version >> 12 & 0x3FF)
}

/// A C struct in the versions this library reads, each the one before with fields appended.
///
/// # Safety
/// Implementors are `#[repr(C)]`; every bit pattern of their fields is valid (integers, floats, raw
/// pointers, optional function pointers); each size in `SIZES` but the last ends before the fields of
/// the versions after it begin.
pub(crate) unsafe trait Versions: Sized {
    /// `sizeof` of the struct in the versions this library reads, oldest first, with the minor version
    /// that gave it that size; the last is this library's.
    const SIZES: &'static [(usize, u32)];

    /// The value of the fields a version lacks: their documented defaults, all zeros unless a type says
    /// otherwise.
    fn defaults() -> Self {
        // SAFETY: every bit pattern of the fields is valid (trait contract), all zeros among them.
        unsafe { std::mem::zeroed() }
    }
}

/// A struct that starts with `u32 struct_size`, the `sizeof` of the caller's version.
///
/// # Safety
/// As for [`Versions`]; the first field is `struct_size: u32`.
pub(crate) unsafe trait Versioned: Versions {}

macro_rules! versions {
    ($($t:ty => [$(($size:literal, $minor:literal)),+] $($versioned:ident)?;)*) => {$(
        // SAFETY: `#[repr(C)]` of integers, floats, raw and optional function pointers (types.rs); the
        // older sizes end where later fields begin (checked below).
        unsafe impl Versions for $t {
            const SIZES: &'static [(usize, u32)] = &[$(($size, $minor)),+];
        }
        const _: () = assert!(
            <$t as Versions>::SIZES[<$t as Versions>::SIZES.len() - 1].0 == size_of::<$t>(),
            "the last size is this library's"
        );
        $(versions!(@$versioned $t);)?
    )*};
    (@versioned $t:ty) => {
        // SAFETY: as above; the first field is `struct_size: u32` (types.rs).
        unsafe impl Versioned for $t {}
    };
}

// Each struct's (size, minor version that gave it that size), oldest first.
versions! {
    HrtsAllocationCallbacks => [(32, 1)] versioned;
    HrtsMemoryStats => [(32, 1)] versioned;
    HrtsVulkanDevice => [(80, 1)] versioned;
    HrtsContextCreateInfo => [(32, 1)] versioned;
    HrtsCapabilities => [(176, 1)] versioned;
    HrtsCpuGeometry => [(56, 1), (64, 8)] versioned;
    HrtsVulkanGeometry => [(136, 1), (144, 8)] versioned;
    HrtsTargets => [(80, 1)] versioned;
    HrtsFrame => [(240, 1), (256, 8)] versioned;
    HrtsResourceInfo => [(32, 1)] versioned;
    HrtsResourceReadback => [(48, 1)] versioned;
    HrtsFrameReport => [(5560, 1), (5568, 4), (5592, 9), (5600, 10), (5608, 11)] versioned;
    HrtsLightPlan => [(156, 10), (160, 11)] versioned;
    HrtsDraw => [(76, 1)];
    HrtsLight => [(100, 1)];
    HrtsMeshVertices => [(32, 1)];
}

// SAFETY: as for the structs above; 104, 108, 112 and 120 end where `map_initial_pairs`, `area_samples`,
// `map_list_limit` and `area_walk_budget` begin.
unsafe impl Versions for HrtsConfig {
    const SIZES: &'static [(usize, u32)] = &[(104, 1), (108, 4), (112, 5), (120, 9), (124, 10)];

    /// A configuration of 5.1 to 5.3 gets `map_initial_pairs` 0 (automatic); one of 5.1 to 5.4
    /// `area_samples` 64; one of 5.1 to 5.8 the default list limit and bin budget; one of 5.1 to 5.9 the
    /// default area walk budget: the defaults of `hrts_config_defaults`.
    fn defaults() -> Self {
        // SAFETY: every field is an integer or a float: all zeros is valid.
        let mut config: Self = unsafe { std::mem::zeroed() };
        let defaults = passes::ShadowConfig::default();
        config.area_samples = defaults.area.samples;
        config.map_list_limit = defaults.map.list_limit;
        config.map_bin_budget = defaults.map.bin_budget;
        config.area_walk_budget = defaults.area.bundle_walk_budget;
        config
    }
}
// SAFETY: as above; the first field is `struct_size: u32`.
unsafe impl Versioned for HrtsConfig {}
const _: () = assert!(HrtsConfig::SIZES[4].0 == size_of::<HrtsConfig>());

// The fields of each version lie past the sizes of the versions before it, never in their padding.
const _: () = {
    assert!(offset_of!(HrtsCpuGeometry, draw_stride) == 56);
    assert!(offset_of!(HrtsVulkanGeometry, draw_stride) == 136);
    assert!(offset_of!(HrtsFrame, light_stride) == 240);
    assert!(offset_of!(HrtsFrameReport, bin_pairs) == 5560);
    assert!(offset_of!(HrtsConfig, map_initial_pairs) == 104);
    assert!(offset_of!(HrtsConfig, area_samples) == 108);
    assert!(offset_of!(HrtsConfig, map_list_limit) == 112);
    assert!(offset_of!(HrtsFrameReport, texels_past_limit) == 5568);
    assert!(offset_of!(HrtsFrameReport, pixels_walked_per_sample) == 5592);
    assert!(offset_of!(HrtsFrameReport, map_size) == 5600);
    assert!(offset_of!(HrtsLightPlan, map_size) == 156);
    assert!(offset_of!(HrtsConfig, area_walk_budget) == 120);
};

/// The name of `T` in the C header.
fn c_name<T>() -> &'static str {
    let name = std::any::type_name::<T>();
    name.rsplit("::").next().unwrap_or(name)
}

/// Checks `size`, a caller's `struct_size` or the stride of its array of `T` (`what` names it), is the
/// size of a version of `T` this library reads.
pub(crate) fn check_size<T: Versions>(size: usize, what: &str) -> ApiResult<()> {
    if T::SIZES.iter().any(|&(s, _)| s == size) {
        return Ok(());
    }
    let name = c_name::<T>();
    let (ours, minor) = T::SIZES[T::SIZES.len() - 1];
    let major = HRTS_API_VERSION >> 22;
    let message = if size > ours {
        format!(
            "{what} is {size}: larger than this library's {name} ({ours} bytes, API {major}.{minor}): the caller's header is newer than the library"
        )
    } else {
        let known: Vec<String> = T::SIZES
            .iter()
            .map(|&(s, m)| format!("{s} (API {major}.{m})"))
            .collect();
        format!(
            "{what} is {size}: the {name} of no API version this library reads has that size ({}): header/library mismatch",
            known.join(", ")
        )
    };
    Err(ApiError::new(HrtsResult::ErrorStructSize, message))
}

/// The caller's `T` of `size` bytes at `p`: the fields its version has, and the defaults of the others.
///
/// # Safety
/// `p` points at `size` readable bytes, a size of `T::SIZES`.
unsafe fn read_prefix<T: Versions>(p: *const u8, size: usize) -> T {
    let mut value = T::defaults();
    // SAFETY: `size` is at most `size_of::<T>()` (a version's size) and `p` is readable for it (caller);
    // any bytes are valid for `T`'s fields (trait contract).
    unsafe { std::ptr::copy_nonoverlapping(p, (&raw mut value).cast::<u8>(), size) };
    value
}

/// The `struct_size` of the caller's versioned struct at `p` (`what` names it), checked: `p` is not NULL,
/// aligned, and the size is a version's.
fn versioned_size<T: Versioned>(p: *const T, what: &str) -> ApiResult<usize> {
    if p.is_null() {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            format!("{what} is NULL"),
        ));
    }
    check_aligned(p, what)?;
    // SAFETY: a non-NULL pointer passed to the C ABI points at a struct of this family whatever its
    // version (documented contract), and every version starts with the `u32` size; it is aligned.
    let size = unsafe { p.cast::<u32>().read() } as usize;
    check_size::<T>(size, &format!("{}.struct_size", c_name::<T>()))?;
    Ok(size)
}

/// Reads the caller's versioned struct at `p` (`what` names it), of whatever version this library reads.
pub(crate) fn read<T: Versioned>(p: *const T, what: &str) -> ApiResult<T> {
    let size = versioned_size(p, what)?;
    // SAFETY: the caller's struct holds `struct_size` bytes (documented contract), a version's size.
    Ok(unsafe { read_prefix(p.cast(), size) })
}

/// Fills the caller's versioned struct at `p` (`what` names it) through `fill`, from the defaults (fields
/// `fill` leaves are zero), and writes only the bytes the caller's version holds; its `struct_size` stays
/// the caller's.
pub(crate) fn write<T: Versioned>(
    p: *mut T,
    what: &str,
    fill: impl FnOnce(&mut T) -> ApiResult<()>,
) -> ApiResult<()> {
    let size = versioned_size(p, what)?;
    let mut value = T::defaults();
    fill(&mut value)?;
    // SAFETY: the first field of `T` is the `u32` struct size (trait contract).
    unsafe { (&raw mut value).cast::<u32>().write(size as u32) };
    // SAFETY: the caller's struct holds `size` writable bytes and the plugin has exclusive use of it during
    // the call (documented contract); `size` is at most `size_of::<T>()`.
    unsafe { std::ptr::copy_nonoverlapping((&raw const value).cast::<u8>(), p.cast::<u8>(), size) };
    Ok(())
}

/// Reads an array of `count` versioned structs at `p` (`what` names it): the first's `struct_size` is the
/// stride, and every one must have it.
pub(crate) fn read_array<T: Versioned>(p: *const T, count: usize, what: &str) -> ApiResult<Vec<T>> {
    let stride = versioned_size(p, what)?;
    (0..count)
        .map(|i| {
            // SAFETY: the caller's array holds `count` structs `stride` bytes apart (documented contract).
            let at = unsafe { p.byte_add(i * stride) };
            // SAFETY: as above; `at` is aligned (`p` is, and a version's size is a multiple of `T`'s
            // alignment) and starts with the `u32` size.
            let size = unsafe { at.cast::<u32>().read() } as usize;
            if size != stride {
                return Err(ApiError::new(
                    HrtsResult::ErrorStructSize,
                    format!(
                        "{what}[{i}].struct_size is {size}, {what}[0]'s {stride}: an array holds structs of one version"
                    ),
                ));
            }
            // SAFETY: as above.
            Ok(unsafe { read_prefix(at.cast(), stride) })
        })
        .collect()
}

/// Checks the caller's array of `count` versioned structs at `p` (`what` names it) before it is written:
/// the first's `struct_size` is the stride, and every one must have it. Returns the stride.
pub(crate) fn check_array<T: Versioned>(p: *const T, count: usize, what: &str) -> ApiResult<usize> {
    let stride = versioned_size(p, what)?;
    for i in 0..count {
        // SAFETY: the caller's array holds `count` structs `stride` bytes apart (documented contract); each
        // is aligned (`p` is, and a version's size is a multiple of `T`'s alignment) and starts with the
        // `u32` size.
        let size = unsafe { p.byte_add(i * stride).cast::<u32>().read() } as usize;
        if size != stride {
            return Err(ApiError::new(
                HrtsResult::ErrorStructSize,
                format!(
                    "{what}[{i}].struct_size is {size}, {what}[0]'s {stride}: an array holds structs of one version"
                ),
            ));
        }
    }
    Ok(stride)
}

/// Fills the caller's array of structs at `p`, checked by [`check_array`] (`stride` bytes apart), with
/// `values` as [`write`] fills one.
pub(crate) fn write_array<T: Versioned + Copy>(
    p: *mut T,
    stride: usize,
    what: &str,
    values: &[T],
) -> ApiResult<()> {
    for (i, value) in values.iter().enumerate() {
        // SAFETY: the caller's array holds `values.len()` structs `stride` bytes apart (checked sizes).
        let at = unsafe { p.byte_add(i * stride) };
        write(at, what, |out| {
            *out = *value;
            Ok(())
        })?;
    }
    Ok(())
}

/// Reads `count` elements of `T` at `p` (`what` names the array), `stride` bytes apart: the caller's
/// `sizeof(T)`, a version's size, or 0 for the oldest version's. `p` may be NULL if `count` is 0.
pub(crate) fn read_elements<T: Versions>(
    p: *const T,
    count: usize,
    stride: usize,
    what: &str,
) -> ApiResult<Vec<T>> {
    if count == 0 {
        return Ok(Vec::new());
    }
    if p.is_null() {
        return Err(ApiError::new(
            HrtsResult::ErrorNullPointer,
            format!("{what} is NULL"),
        ));
    }
    let stride = match stride {
        0 => T::SIZES[0].0,
        given => given,
    };
    check_size::<T>(
        stride,
        &format!("the stride of {what} (sizeof({}))", c_name::<T>()),
    )?;
    check_aligned(p, what)?;
    Ok((0..count)
        .map(|i| {
            // SAFETY: the caller's array holds `count` elements `stride` bytes apart (documented contract),
            // a version's size.
            unsafe { read_prefix(p.cast::<u8>().add(i * stride), stride) }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use passes::ShadowConfig;

    /// This library's defaults, as a caller gets them (`hrts_config_defaults`).
    fn default_config() -> HrtsConfig {
        let mut c = <HrtsConfig as Versions>::defaults();
        c.struct_size = size_of::<HrtsConfig>() as u32;
        // SAFETY: `c` is a live, aligned `HrtsConfig` of this library's size.
        assert_eq!(
            unsafe { crate::hrts_config_defaults(&mut c) },
            HrtsResult::Ok
        );
        c
    }

    /// A type's sizes grow with their minor versions, from the oldest read to this library's.
    fn sizes_grow<T: Versions>() {
        let sizes = T::SIZES;
        assert_eq!(sizes[0].1, OLDEST_MINOR, "{}", c_name::<T>());
        assert!(sizes[sizes.len() - 1].1 <= major_minor(HRTS_API_VERSION).1);
        for pair in sizes.windows(2) {
            assert!(
                pair[0].0 < pair[1].0 && pair[0].1 < pair[1].1,
                "{}",
                c_name::<T>()
            );
        }
    }

    #[test]
    fn sizes_grow_with_their_minor_versions() {
        sizes_grow::<HrtsAllocationCallbacks>();
        sizes_grow::<HrtsMemoryStats>();
        sizes_grow::<HrtsVulkanDevice>();
        sizes_grow::<HrtsContextCreateInfo>();
        sizes_grow::<HrtsCapabilities>();
        sizes_grow::<HrtsConfig>();
        sizes_grow::<HrtsCpuGeometry>();
        sizes_grow::<HrtsVulkanGeometry>();
        sizes_grow::<HrtsTargets>();
        sizes_grow::<HrtsFrame>();
        sizes_grow::<HrtsResourceInfo>();
        sizes_grow::<HrtsResourceReadback>();
        sizes_grow::<HrtsFrameReport>();
        sizes_grow::<HrtsDraw>();
        sizes_grow::<HrtsLight>();
        sizes_grow::<HrtsMeshVertices>();
    }

    #[test]
    fn an_older_configuration_reads_the_defaults_of_its_newer_fields() {
        let mut c = default_config();
        // Bytes past an older caller's struct: never read as its fields.
        (c.map_initial_pairs, c.area_samples, c.map_size) = (77, 9, 333);
        let mut fields = |size: u32| {
            c.struct_size = size;
            let r = read(&c, "config").unwrap();
            (
                r.struct_size,
                r.map_size,
                r.map_initial_pairs,
                r.area_samples,
            )
        };
        assert_eq!(fields(104), (104, 333, 0, 64), "API 5.1");
        assert_eq!(fields(108), (108, 333, 77, 64), "API 5.4");
        assert_eq!(fields(112), (112, 333, 77, 9), "API 5.5");
        // A 5.8 configuration gets the default list limit and bin budget.
        (c.map_list_limit, c.map_bin_budget) = (3, 0.5);
        c.struct_size = 112;
        let old = read(&c, "config").unwrap();
        let defaults = ShadowConfig::default().map;
        assert_eq!(
            (old.map_list_limit, old.map_bin_budget),
            (defaults.list_limit, defaults.bin_budget)
        );
        c.struct_size = 120;
        let new = read(&c, "config").unwrap();
        assert_eq!((new.map_list_limit, new.map_bin_budget), (3, 0.5));
    }

    #[test]
    fn a_struct_is_written_up_to_the_callers_size() {
        let mut storage = std::mem::MaybeUninit::<HrtsFrameReport>::uninit();
        let p = storage.as_mut_ptr();
        let bytes = size_of::<HrtsFrameReport>();
        // SAFETY: `p` holds `bytes` writable bytes.
        unsafe {
            p.cast::<u8>().write_bytes(0xA5, bytes);
            p.cast::<u32>().write(5560);
        }
        write(p, "out", |out| {
            (out.entries, out.bin_pairs, out.bin_pair_capacity) = (7, 9, 9);
            Ok(())
        })
        .unwrap();
        // SAFETY: every byte was written above.
        let written = unsafe { std::slice::from_raw_parts(p.cast::<u8>(), bytes) };
        assert!(
            written[5560..].iter().all(|&b| b == 0xA5),
            "past the caller's 5.1 report"
        );
        // SAFETY: as above; the fields are integers.
        let (size, entries) = unsafe { ((*p).struct_size, (*p).entries) };
        assert_eq!((size, entries), (5560, 7));
    }

    #[test]
    fn sizes_of_no_version_are_refused_with_the_sizes_read() {
        let message = |size| {
            let e = check_size::<HrtsFrame>(size, "HrtsFrame.struct_size").unwrap_err();
            assert_eq!(e.code, HrtsResult::ErrorStructSize);
            e.message
        };
        assert!(
            check_size::<HrtsFrame>(240, "").is_ok() && check_size::<HrtsFrame>(256, "").is_ok()
        );
        let between = message(248);
        assert!(
            between.contains("240 (API 5.1), 256 (API 5.8)"),
            "{between}"
        );
        let newer = message(264);
        assert!(newer.contains("newer than the library"), "{newer}");
    }

    #[test]
    fn elements_are_read_at_the_callers_stride() {
        let light = |k: f32| HrtsLight {
            light_type: 0,
            position: [k; 3],
            direction: [0.0, -1.0, 0.0],
            view_proj: [k; 16],
            range: k,
            outer_cone: 0.5,
        };
        let lights = [light(1.0), light(2.0)];
        for stride in [0, size_of::<HrtsLight>()] {
            assert_eq!(
                read_elements(lights.as_ptr(), 2, stride, "lights").unwrap(),
                lights
            );
        }
        for stride in [96, 104] {
            let e = read_elements(lights.as_ptr(), 2, stride, "lights").unwrap_err();
            assert_eq!(e.code, HrtsResult::ErrorStructSize, "{}", e.message);
            assert!(e.message.contains("stride of lights"), "{}", e.message);
        }
        let none: Vec<HrtsLight> = read_elements(std::ptr::null(), 0, 0, "lights").unwrap();
        assert!(none.is_empty());
        let e = read_elements::<HrtsLight>(std::ptr::null(), 1, 0, "lights").unwrap_err();
        assert_eq!(e.code, HrtsResult::ErrorNullPointer);
    }

    #[test]
    fn an_array_holds_structs_of_one_version() {
        let c = default_config();
        let mut older = default_config();
        older.struct_size = 108;
        assert_eq!(read_array(&c, 1, "configs").unwrap().len(), 1);
        let mixed = [c, older];
        let e = read_array(mixed.as_ptr(), 2, "configs")
            .map(|_| ())
            .unwrap_err();
        assert_eq!(e.code, HrtsResult::ErrorStructSize);
        assert!(
            e.message.contains("configs[1].struct_size is 108"),
            "{}",
            e.message
        );
    }
}
