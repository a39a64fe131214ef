//! Reading accessors with every offset, stride and length checked (the gltf crate's reader
//! trusts them and can panic or overflow on malformed files), from buffer views that may be
//! meshopt-compressed.

use std::cell::OnceCell;

use glam::Vec3;
use gltf::accessor::{DataType, Dimensions};

use super::compression;

/// Most elements of an accessor without a buffer view (all zeros, plus sparse values).
const MAX_UNBACKED_ELEMENTS: usize = 1 << 24;

/// The bytes of a file's buffers, and of its compressed buffer views once decoded.
pub(super) struct BufferData {
    /// Each buffer's bytes; `None` for a placeholder without data (the uncompressed fallback of
    /// meshopt-compressed views, which the file does not provide).
    buffers: Vec<Option<Vec<u8>>>,
    /// Each buffer view's decoded bytes, for compressed views that were read.
    decoded: Vec<OnceCell<Vec<u8>>>,
}

impl BufferData {
    /// `buffers` of a document with `view_count` buffer views.
    pub(super) fn new(buffers: Vec<Option<Vec<u8>>>, view_count: usize) -> Self {
        Self {
            buffers,
            decoded: (0..view_count).map(|_| OnceCell::new()).collect(),
        }
    }

    fn buffer(&self, index: usize) -> Result<&[u8], String> {
        match self.buffers.get(index) {
            Some(Some(bytes)) => Ok(bytes),
            Some(None) => Err(format!(
                "buffer {index} has no data: it is the placeholder of meshopt-compressed buffer views, read only through their extension"
            )),
            None => Err(format!(
                "buffer {index} does not exist ({} buffers)",
                self.buffers.len()
            )),
        }
    }

    /// The bytes of buffer view `view`: decoded if it is meshopt-compressed, unless the codec
    /// is unknown and the view's own buffer holds the uncompressed data.
    fn view(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        if let Some((extension, compression)) = compression::compression(view) {
            let compression = compression?;
            let has_fallback = matches!(self.buffers.get(view.buffer().index()), Some(Some(_)));
            if !(compression::is_unknown(extension, &compression) && has_fallback) {
                if let Some(decoded) = self.decoded[view.index()].get() {
                    return Ok(decoded);
                }
                let error = |m: String| format!("buffer view {}: {extension}: {m}", view.index());
                let buffer = self.buffer(compression.buffer).map_err(error)?;
                let compressed = compression
                    .byte_offset
                    .checked_add(compression.byte_length)
                    .and_then(|end| buffer.get(compression.byte_offset..end))
                    .ok_or_else(|| {
                        error(format!(
                            "compressed bytes {} + {} exceed buffer {} of {} bytes",
                            compression.byte_offset,
                            compression.byte_length,
                            compression.buffer,
                            buffer.len()
                        ))
                    })?;
                let decoded =
                    compression::decode(&compression, view.length(), view.stride(), compressed)
                        .map_err(error)?;
                return Ok(self.decoded[view.index()].get_or_init(|| decoded));
            }
        }
        let buffer = self.buffer(view.buffer().index())?;
        view.offset()
            .checked_add(view.length())
            .and_then(|end| buffer.get(view.offset()..end))
            .ok_or_else(|| {
                format!(
                    "buffer view {} (bytes {} + {}) exceeds buffer {} of {} bytes",
                    view.index(),
                    view.offset(),
                    view.length(),
                    view.buffer().index(),
                    buffer.len()
                )
            })
    }
}

/// The elements of a `POSITION` accessor: `VEC3` of `FLOAT`, or, as `KHR_mesh_quantization`
/// allows, of (normalized or not) `BYTE`, `UNSIGNED_BYTE`, `SHORT` or `UNSIGNED_SHORT`.
/// Integers become floats exactly; normalized ones are divided as the glTF specification says
/// (`max(c / 127, -1)`, `c / 255`, `max(c / 32767, -1)`, `c / 65535`), correctly rounded.
pub(super) fn read_positions(
    accessor: &gltf::Accessor,
    data: &BufferData,
) -> Result<Vec<Vec3>, String> {
    type Dequantize = fn(&[u8]) -> f32;
    let i8_at = |b: &[u8]| f32::from(b[0] as i8);
    let i16_at = |b: &[u8]| f32::from(i16::from_le_bytes([b[0], b[1]]));
    let u16_at = |b: &[u8]| f32::from(u16::from_le_bytes([b[0], b[1]]));
    let (size, component): (usize, Dequantize) = match (accessor.data_type(), accessor.normalized())
    {
        (DataType::F32, _) => (4, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        (DataType::I8, false) => (1, i8_at),
        (DataType::I8, true) => (1, |b| (f32::from(b[0] as i8) / 127.0).max(-1.0)),
        (DataType::U8, false) => (1, |b| f32::from(b[0])),
        (DataType::U8, true) => (1, |b| f32::from(b[0]) / 255.0),
        (DataType::I16, false) => (2, i16_at),
        (DataType::I16, true) => (2, |b| {
            (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }),
        (DataType::U16, false) => (2, u16_at),
        (DataType::U16, true) => (2, |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0),
        (other, _) => return Err(position_type_error(accessor.dimensions(), other)),
    };
    if accessor.dimensions() != Dimensions::Vec3 {
        return Err(position_type_error(
            accessor.dimensions(),
            accessor.data_type(),
        ));
    }
    let bytes = read_packed(accessor, data, 3 * size)?;
    Ok(bytes
        .chunks_exact(3 * size)
        .map(|v| {
            Vec3::new(
                component(&v[..size]),
                component(&v[size..2 * size]),
                component(&v[2 * size..]),
            )
        })
        .collect())
}

fn position_type_error(dimensions: Dimensions, data_type: DataType) -> String {
    format!(
        "POSITION must be VEC3 of FLOAT (or, with KHR_mesh_quantization, of BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT), found {dimensions:?} of {data_type:?}"
    )
}

/// The elements of a `SCALAR` index accessor of unsigned bytes, shorts or ints.
pub(super) fn read_indices(
    accessor: &gltf::Accessor,
    data: &BufferData,
) -> Result<Vec<u32>, String> {
    let size = match accessor.data_type() {
        DataType::U8 => 1,
        DataType::U16 => 2,
        DataType::U32 => 4,
        other => {
            return Err(format!(
                "indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, found {other:?}"
            ))
        }
    };
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(format!(
            "indices must be SCALAR, found {:?}",
            accessor.dimensions()
        ));
    }
    let bytes = read_packed(accessor, data, size)?;
    Ok(bytes.chunks_exact(size).map(unsigned).collect())
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn unsigned(bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .rev()
        .fold(0u32, |value, &b| (value << 8) | u32::from(b))
}

/// `length` bytes from `offset` of buffer view `view`.
fn view_range<'b>(
    view: &gltf::buffer::View,
    offset: usize,
    length: usize,
    data: &'b BufferData,
) -> Result<&'b [u8], String> {
    let bytes = data.view(view)?;
    offset
        .checked_add(length)
        .and_then(|end| bytes.get(offset..end))
        .ok_or_else(|| {
            format!(
                "{length} bytes from byte offset {offset} exceed buffer view {} of {} bytes",
                view.index(),
                bytes.len()
            )
        })
}

/// The accessor's elements of `size` bytes each, packed, with sparse values substituted.
fn read_packed(
    accessor: &gltf::Accessor,
    data: &BufferData,
    size: usize,
) -> Result<Vec<u8>, String> {
    let count = accessor.count();
    if count == 0 {
        return Err("count is 0".into());
    }
    let too_large = || format!("{count} elements of {size} bytes are too many");
    let total = count.checked_mul(size).ok_or_else(too_large)?;
    let mut packed = match accessor.view() {
        Some(view) => {
            let bytes = data.view(&view)?;
            let stride = view.stride().unwrap_or(size);
            if stride < size {
                return Err(format!(
                    "byteStride {stride} of buffer view {} is less than the element size {size}",
                    view.index()
                ));
            }
            let offset = accessor.offset();
            let end = (count - 1)
                .checked_mul(stride)
                .and_then(|e| e.checked_add(offset))
                .and_then(|e| e.checked_add(size));
            if end.is_none_or(|end| end > bytes.len()) {
                return Err(format!(
                    "{count} elements of {size} bytes with stride {stride} from byte offset {offset} exceed buffer view {} of {} bytes",
                    view.index(),
                    bytes.len()
                ));
            }
            let mut packed = Vec::with_capacity(total);
            for i in 0..count {
                let start = offset + i * stride;
                packed.extend_from_slice(&bytes[start..start + size]);
            }
            packed
        }
        None if count > MAX_UNBACKED_ELEMENTS => return Err(too_large()),
        None => vec![0; total],
    };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n == 0 || n > count {
            return Err(format!(
                "sparse count {n} is not in [1, accessor count {count}]"
            ));
        }
        let indices = sparse.indices();
        let index_size = indices.index_type().size();
        let index_length = n.checked_mul(index_size).ok_or_else(too_large)?;
        let index_bytes = view_range(&indices.view(), indices.offset(), index_length, data)
            .map_err(|m| format!("sparse indices: {m}"))?;
        let values = sparse.values();
        let value_bytes = view_range(&values.view(), values.offset(), n * size, data)
            .map_err(|m| format!("sparse values: {m}"))?;
        for (index, value) in index_bytes
            .chunks_exact(index_size)
            .map(unsigned)
            .zip(value_bytes.chunks_exact(size))
        {
            let index = index as usize;
            if index >= count {
                return Err(format!(
                    "sparse index {index} is out of range for {count} elements"
                ));
            }
            packed[index * size..(index + 1) * size].copy_from_slice(value);
        }
    }
    Ok(packed)
}
