//! Buffer views compressed with `EXT_meshopt_compression` or `KHR_meshopt_compression`, decoded
//! with meshoptimizer's decoders (the `meshopt` crate).
//!
//! Every size is checked before anything is allocated: the decoded size is the extension's
//! `count × byteStride`, which must equal the buffer view's `byteLength`, and it must not exceed
//! what the compressed bytes can hold at the codec's largest expansion (the decoders need at
//! least that many bytes, so no valid stream is refused). The decoders return an error for a
//! stream that is short or malformed; they never read or write out of bounds.

use serde::Deserialize;

/// The extension names, in order of preference when a buffer view has both.
pub(super) const EXTENSIONS: [&str; 2] = ["KHR_meshopt_compression", "EXT_meshopt_compression"];

/// The largest expansion of the attribute codec: a block of up to 256 elements needs at least
/// one control byte per 4 bytes of element (format 1), and 4 × 256 = 1024.
const MAX_ATTRIBUTE_EXPANSION: usize = 1024;

/// The extension object of a compressed buffer view.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Compression {
    /// The buffer holding the compressed bytes.
    pub(super) buffer: usize,
    #[serde(default)]
    pub(super) byte_offset: usize,
    /// Length of the compressed bytes.
    pub(super) byte_length: usize,
    pub(super) byte_stride: usize,
    pub(super) count: usize,
    pub(super) mode: String,
    #[serde(default = "no_filter")]
    pub(super) filter: String,
}

fn no_filter() -> String {
    "NONE".to_owned()
}

/// The compression of `view`, if one of [`EXTENSIONS`] is on it, with the extension's name.
pub(super) fn compression(
    view: &gltf::buffer::View,
) -> Option<(&'static str, Result<Compression, String>)> {
    EXTENSIONS.iter().find_map(|&name| {
        view.extension_value(name).map(|value| {
            let parsed = Compression::deserialize(value)
                .map_err(|e| format!("buffer view {}: {name}: {e}", view.index()));
            (name, parsed)
        })
    })
}

/// Whether the codec or filter of `compression` is one this decoder does not know; such a view
/// is read from its uncompressed fallback where the file provides one.
pub(super) fn is_unknown(extension: &str, compression: &Compression) -> bool {
    let filters: &[&str] = match extension {
        "KHR_meshopt_compression" => &["NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL", "COLOR"],
        _ => &["NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"],
    };
    !["ATTRIBUTES", "TRIANGLES", "INDICES"].contains(&compression.mode.as_str())
        || !filters.contains(&compression.filter.as_str())
}

/// Decodes `compressed` (the extension's byte range) into the `view_length` bytes of the
/// buffer view, after checking every size against the extension's rules.
pub(super) fn decode(
    compression: &Compression,
    view_length: usize,
    view_stride: Option<usize>,
    compressed: &[u8],
) -> Result<Vec<u8>, String> {
    let Compression {
        byte_stride: stride,
        count,
        ref mode,
        ref filter,
        ..
    } = *compression;
    let decoded_length = count
        .checked_mul(stride)
        .ok_or_else(|| format!("{count} elements of {stride} bytes are too many"))?;
    if decoded_length != view_length {
        return Err(format!(
            "count {count} × byteStride {stride} = {decoded_length} bytes, but the buffer view's byteLength is {view_length}"
        ));
    }
    if view_stride.is_some_and(|s| s != stride) {
        return Err(format!(
            "byteStride {stride} differs from the buffer view's byteStride {}",
            view_stride.unwrap_or_default()
        ));
    }
    let length = compressed.len();
    let too_short = |needed: &str| {
        Err(format!(
            "{length} compressed bytes cannot hold {count} elements of {stride} bytes in mode {mode} ({needed})"
        ))
    };
    match mode.as_str() {
        "ATTRIBUTES" => {
            if stride == 0 || stride % 4 != 0 || stride > 256 {
                return Err(format!(
                    "mode ATTRIBUTES needs a byteStride divisible by 4 and at most 256, found {stride}"
                ));
            }
            if decoded_length > length.saturating_mul(MAX_ATTRIBUTE_EXPANSION) {
                return too_short("the codec expands at most 1024 times");
            }
            // The filter and stride are checked on no data before anything is decoded.
            apply_filter(&mut [], filter, stride)?;
            let mut data = decode_attributes(compressed, count, stride)?;
            apply_filter(&mut data, filter, stride)?;
            Ok(data)
        }
        "TRIANGLES" | "INDICES" => {
            if filter != "NONE" {
                return Err(format!("mode {mode} takes no filter, found {filter}"));
            }
            if stride != 2 && stride != 4 {
                return Err(format!(
                    "mode {mode} needs a byteStride of 2 or 4, found {stride}"
                ));
            }
            if mode == "TRIANGLES" {
                if count % 3 != 0 {
                    return Err(format!(
                        "mode TRIANGLES needs a count divisible by 3, found {count}"
                    ));
                }
                // The codec stores at least one byte per triangle, a header and a 16-byte table.
                if count / 3 + 17 > length {
                    return too_short("at least 1 byte per triangle and 17 more");
                }
                decode_indices(compressed, count, stride, true)
            } else {
                // At least one byte per index, a header and a 4-byte tail.
                if count.saturating_add(5) > length {
                    return too_short("at least 1 byte per index and 5 more");
                }
                decode_indices(compressed, count, stride, false)
            }
        }
        other => Err(format!(
            "unknown mode \"{other}\" (ATTRIBUTES, TRIANGLES or INDICES)"
        )),
    }
}

/// One element of `N` bytes, for the attribute decoder (whose element size is a type's size).
#[derive(Clone, Copy)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

fn decode_elements<const N: usize>(compressed: &[u8], count: usize) -> Result<Vec<u8>, String> {
    let elements = meshopt::decode_vertex_buffer::<Element<N>>(compressed, count)
        .map_err(|e| format!("corrupt ATTRIBUTES stream: {e}"))?;
    let mut bytes = Vec::with_capacity(count * N);
    for element in &elements {
        bytes.extend_from_slice(&element.0);
    }
    Ok(bytes)
}

/// Generates the dispatch from a runtime element size to [`decode_elements`].
macro_rules! decode_by_stride {
    ($compressed:expr, $count:expr, $stride:expr, $($n:literal)*) => {
        match $stride {
            $($n => decode_elements::<$n>($compressed, $count),)*
            other => Err(format!("unsupported byteStride {other}")),
        }
    };
}

/// The attribute codec's output for `count` elements of `stride` bytes (a multiple of 4, at most
/// 256).
fn decode_attributes(compressed: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    decode_by_stride!(compressed, count, stride,
        4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108 112 116
        120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196 200 204
        208 212 216 220 224 228 232 236 240 244 248 252 256)
}

/// The index codec's output (triangle lists if `triangles`, else index sequences) as
/// little-endian indices of `size` (2 or 4) bytes.
fn decode_indices(
    compressed: &[u8],
    count: usize,
    size: usize,
    triangles: bool,
) -> Result<Vec<u8>, String> {
    let corrupt = |e: meshopt::Error| {
        format!(
            "corrupt {} stream: {e}",
            if triangles { "TRIANGLES" } else { "INDICES" }
        )
    };
    Ok(if size == 2 {
        let indices: Vec<u16> = if triangles {
            meshopt::decode_index_buffer(compressed, count)
        } else {
            meshopt::decode_index_sequence(compressed, count)
        }
        .map_err(corrupt)?;
        indices.iter().flat_map(|i| i.to_le_bytes()).collect()
    } else {
        let indices: Vec<u32> = if triangles {
            meshopt::decode_index_buffer(compressed, count)
        } else {
            meshopt::decode_index_sequence(compressed, count)
        }
        .map_err(corrupt)?;
        indices.iter().flat_map(|i| i.to_le_bytes()).collect()
    })
}

/// Applies the decode filter `filter` in place to elements of `stride` bytes.
fn apply_filter(data: &mut [u8], filter: &str, stride: usize) -> Result<(), String> {
    let wrong_stride = |allowed: &str| {
        Err(format!(
            "filter {filter} needs a byteStride of {allowed}, found {stride}"
        ))
    };
    match (filter, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => filter_elements(data, meshopt::decode_filter_oct::<i8>),
        ("OCTAHEDRAL", 8) => filter_elements(data, meshopt::decode_filter_oct::<i16>),
        ("OCTAHEDRAL", _) => return wrong_stride("4 or 8"),
        ("QUATERNION", 8) => filter_elements(data, meshopt::decode_filter_quat),
        ("QUATERNION", _) => return wrong_stride("8"),
        // Each 32-bit component is decoded on its own, so any multiple of 4 is one-word elements.
        ("EXPONENTIAL", _) => filter_elements(data, meshopt::decode_filter_exp::<1>),
        ("COLOR", 4) => filter_elements(data, meshopt::decode_filter_color::<u8>),
        ("COLOR", 8) => filter_elements(data, meshopt::decode_filter_color::<u16>),
        ("COLOR", _) => return wrong_stride("4 or 8"),
        (other, _) => return Err(format!("unknown filter \"{other}\"")),
    }
    Ok(())
}

/// A component of a filtered element, read and written little-endian.
trait Component: Copy + Default {
    const SIZE: usize;
    fn read(bytes: &[u8]) -> Self;
    fn write(self, bytes: &mut [u8]);
}

macro_rules! component {
    ($($t:ty)*) => {$(
        impl Component for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            fn read(bytes: &[u8]) -> Self {
                <$t>::from_le_bytes(bytes.try_into().unwrap_or_default())
            }
            fn write(self, bytes: &mut [u8]) {
                bytes.copy_from_slice(&self.to_le_bytes());
            }
        }
    )*};
}
component!(i8 u8 i16 u16 u32);

/// Runs `filter` over `data` seen as elements of `K` components of type `C`.
fn filter_elements<C: Component, const K: usize>(data: &mut [u8], filter: fn(&mut [[C; K]])) {
    let mut elements: Vec<[C; K]> = data
        .chunks_exact(C::SIZE * K)
        .map(|e| std::array::from_fn(|k| C::read(&e[k * C::SIZE..(k + 1) * C::SIZE])))
        .collect();
    filter(&mut elements);
    for (element, bytes) in elements.iter().zip(data.chunks_exact_mut(C::SIZE * K)) {
        for (k, c) in element.iter().enumerate() {
            c.write(&mut bytes[k * C::SIZE..(k + 1) * C::SIZE]);
        }
    }
}
