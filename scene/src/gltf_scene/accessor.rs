//! Reading accessors with every offset, stride and length checked (the gltf crate's reader
//! trusts them and can panic or overflow on malformed files).

use glam::Vec3;
use gltf::accessor::{DataType, Dimensions};

/// Most elements of an accessor without a buffer view (all zeros, plus sparse values).
const MAX_UNBACKED_ELEMENTS: usize = 1 << 24;

/// The `VEC3`/`FLOAT` elements of a `POSITION` accessor.
pub(super) fn read_positions(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<Vec3>, String> {
    if accessor.data_type() != DataType::F32 || accessor.dimensions() != Dimensions::Vec3 {
        return Err(format!(
            "POSITION must be VEC3 of FLOAT, found {:?} of {:?}",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let bytes = read_packed(accessor, buffers, 12)?;
    Ok(bytes
        .chunks_exact(12)
        .map(|v| {
            let c = |k: usize| f32::from_le_bytes([v[k], v[k + 1], v[k + 2], v[k + 3]]);
            Vec3::new(c(0), c(4), c(8))
        })
        .collect())
}

/// The elements of a `SCALAR` index accessor of unsigned bytes, shorts or ints.
pub(super) fn read_indices(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
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
    let bytes = read_packed(accessor, buffers, size)?;
    Ok(bytes.chunks_exact(size).map(unsigned).collect())
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn unsigned(bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .rev()
        .fold(0u32, |value, &b| (value << 8) | u32::from(b))
}

/// The bytes of buffer view `view`.
fn view_bytes<'b>(view: &gltf::buffer::View, buffers: &'b [Vec<u8>]) -> Result<&'b [u8], String> {
    let buffer = &buffers[view.buffer().index()];
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

/// `length` bytes from `offset` of buffer view `view`.
fn view_range<'b>(
    view: &gltf::buffer::View,
    offset: usize,
    length: usize,
    buffers: &'b [Vec<u8>],
) -> Result<&'b [u8], String> {
    let bytes = view_bytes(view, buffers)?;
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
    buffers: &[Vec<u8>],
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
            let data = view_bytes(&view, buffers)?;
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
            if end.is_none_or(|end| end > data.len()) {
                return Err(format!(
                    "{count} elements of {size} bytes with stride {stride} from byte offset {offset} exceed buffer view {} of {} bytes",
                    view.index(),
                    data.len()
                ));
            }
            let mut packed = Vec::with_capacity(total);
            for i in 0..count {
                let start = offset + i * stride;
                packed.extend_from_slice(&data[start..start + size]);
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
        let index_bytes = view_range(&indices.view(), indices.offset(), index_length, buffers)
            .map_err(|m| format!("sparse indices: {m}"))?;
        let values = sparse.values();
        let value_bytes = view_range(&values.view(), values.offset(), n * size, buffers)
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
