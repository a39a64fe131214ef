//! Buffers and images, with memory from gpu-allocator and UAV (storage) / SRV (sampled) views.

use crate::conv::Format;
use crate::device::{Device, Shared};
use crate::error::{Result, RhiError, VkResultExt};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Bytes of GPU memory allocations alive in this process, over every device.
static LIVE_GPU_BYTES: AtomicU64 = AtomicU64::new(0);

/// Bytes of GPU memory allocated through the RHI and not yet freed, over every device of the process.
pub fn live_gpu_allocation_bytes() -> u64 {
    LIVE_GPU_BYTES.load(Ordering::SeqCst)
}

/// Returns an allocation to its device's allocator.
fn free_allocation(shared: &Shared, allocation: Allocation) {
    LIVE_GPU_BYTES.fetch_sub(allocation.size(), Ordering::SeqCst);
    if let Ok(mut alloc) = shared.allocator.lock() {
        let _ = alloc.free(allocation);
    }
}

macro_rules! usage_flags {
    ($(#[$doc:meta])* $name:ident { $($(#[$fdoc:meta])* $flag:ident = $bit:expr),* $(,)? }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct $name(u32);
        impl $name {
            $($(#[$fdoc])* pub const $flag: Self = Self(1 << $bit);)*
            /// Whether all bits of `other` are set.
            pub fn contains(self, other: Self) -> bool { self.0 & other.0 == other.0 }
        }
        impl std::ops::BitOr for $name {
            type Output = Self;
            fn bitor(self, rhs: Self) -> Self { Self(self.0 | rhs.0) }
        }
    };
}

usage_flags!(
    /// How a buffer is used.
    BufferUsage {
        /// UAV / SRV structured buffer (storage buffer).
        STORAGE = 0,
        /// Constant buffer.
        UNIFORM = 1,
        /// Vertex buffer.
        VERTEX = 2,
        /// Index buffer.
        INDEX = 3,
        /// Copy source.
        COPY_SRC = 4,
        /// Copy destination.
        COPY_DST = 5,
        /// Read by acceleration-structure builds through its device address (vertex input). Only on a
        /// device with ray tracing: see [`Device::acceleration_structure_input_usage`].
        ACCELERATION_STRUCTURE_INPUT = 6,
    }
);

usage_flags!(
    /// How an image is used.
    ImageUsage {
        /// SRV: sampled in shaders.
        SAMPLED = 0,
        /// UAV: storage image.
        STORAGE = 1,
        /// Render target.
        COLOR_TARGET = 2,
        /// Depth-stencil target.
        DEPTH_TARGET = 3,
        /// Copy source.
        COPY_SRC = 4,
        /// Copy destination (and clears).
        COPY_DST = 5,
    }
);

/// Pure mapping of [`BufferUsage`] to Vulkan usage flags.
pub fn buffer_usage_to_vk(u: BufferUsage) -> vk::BufferUsageFlags {
    let mut f = vk::BufferUsageFlags::empty();
    let map = [
        (BufferUsage::STORAGE, vk::BufferUsageFlags::STORAGE_BUFFER),
        (BufferUsage::UNIFORM, vk::BufferUsageFlags::UNIFORM_BUFFER),
        (BufferUsage::VERTEX, vk::BufferUsageFlags::VERTEX_BUFFER),
        (BufferUsage::INDEX, vk::BufferUsageFlags::INDEX_BUFFER),
        (BufferUsage::COPY_SRC, vk::BufferUsageFlags::TRANSFER_SRC),
        (BufferUsage::COPY_DST, vk::BufferUsageFlags::TRANSFER_DST),
        (
            BufferUsage::ACCELERATION_STRUCTURE_INPUT,
            vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
                | vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR,
        ),
    ];
    for (ours, theirs) in map {
        if u.contains(ours) {
            f |= theirs;
        }
    }
    f
}

/// Pure mapping of [`ImageUsage`] to Vulkan usage flags.
pub fn image_usage_to_vk(u: ImageUsage) -> vk::ImageUsageFlags {
    let mut f = vk::ImageUsageFlags::empty();
    let map = [
        (ImageUsage::SAMPLED, vk::ImageUsageFlags::SAMPLED),
        (ImageUsage::STORAGE, vk::ImageUsageFlags::STORAGE),
        (
            ImageUsage::COLOR_TARGET,
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
        ),
        (
            ImageUsage::DEPTH_TARGET,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        ),
        (ImageUsage::COPY_SRC, vk::ImageUsageFlags::TRANSFER_SRC),
        (ImageUsage::COPY_DST, vk::ImageUsageFlags::TRANSFER_DST),
    ];
    for (ours, theirs) in map {
        if u.contains(ours) {
            f |= theirs;
        }
    }
    f
}

/// A GPU buffer. Host-visible buffers (`CpuToGpu`, `GpuToCpu`) are persistently mapped. A buffer made
/// by [`Device::external_buffer`] belongs to the engine and is never destroyed here.
pub struct Buffer {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
    pub(crate) usage: vk::BufferUsageFlags,
    owned: bool,
}

/// A 2D image or 2D array image with one view over all layers. An image made by
/// [`Device::external_image`] belongs to the engine: only the view is ours.
pub struct Image {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Image,
    pub(crate) view: vk::ImageView,
    allocation: Option<Allocation>,
    format: Format,
    width: u32,
    height: u32,
    layers: u32,
    /// The first array layer of the underlying `VkImage` this image is (0 but for a layer of an engine's
    /// array image, [`Device::external_image_layer`]).
    base_layer: u32,
    usage: ImageUsage,
    owned: bool,
    /// The plugin's own image this one is another view of ([`Image::alias_shared`]), held alive by it.
    keep_alive: Option<Arc<Image>>,
}

/// Description of an image.
#[derive(Debug, Clone)]
pub struct ImageDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// Texel format.
    pub format: Format,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Array layers; 1 gives a plain 2D view, more a 2D-array view.
    pub layers: u32,
    /// Usage.
    pub usage: ImageUsage,
}

impl Device {
    /// Creates a buffer of `size` bytes. Storage buffers are checked against `maxStorageBufferRange`.
    pub fn create_buffer(
        &self,
        name: &str,
        size: u64,
        usage: BufferUsage,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let limit = self.shared.caps.max_storage_buffer_range;
        if usage.contains(BufferUsage::STORAGE) && size > limit {
            return Err(RhiError::Limit {
                what: format!("storage buffer {name}"),
                value: size,
                limit,
            });
        }
        if usage.contains(BufferUsage::ACCELERATION_STRUCTURE_INPUT) {
            self.ray_tracing_support()?;
        }
        self.create_raw_buffer(name, size, buffer_usage_to_vk(usage), location)
    }

    /// The usage a buffer needs to be read by acceleration-structure builds on this device:
    /// [`BufferUsage::ACCELERATION_STRUCTURE_INPUT`] where ray tracing is enabled, none elsewhere.
    pub fn acceleration_structure_input_usage(&self) -> BufferUsage {
        if self.ray_tracing_support().is_ok() {
            BufferUsage::ACCELERATION_STRUCTURE_INPUT
        } else {
            BufferUsage::default()
        }
    }

    /// Creates a buffer of `size` bytes with raw Vulkan usage flags.
    pub(crate) fn create_raw_buffer(
        &self,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        if size == 0 {
            return Err(RhiError::InvalidArgument(format!(
                "buffer {name} has size 0"
            )));
        }
        let d = &self.shared.device;
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info; the buffer is destroyed in Drop (or below on failure).
        let raw = unsafe { d.create_buffer(&info, None) }.call("vkCreateBuffer")?;
        // SAFETY: `raw` is a live buffer of this device.
        let requirements = unsafe { d.get_buffer_memory_requirements(raw) };
        let allocation = self
            .allocate(name, requirements, location, true)
            .and_then(|a| {
                // SAFETY: the allocation satisfies `requirements` and is not bound elsewhere.
                match unsafe { d.bind_buffer_memory(raw, a.memory(), a.offset()) } {
                    Ok(()) => Ok(a),
                    Err(result) => {
                        free_allocation(&self.shared, a);
                        Err(RhiError::Vulkan {
                            call: "vkBindBufferMemory",
                            result,
                        })
                    }
                }
            });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `raw` is unused.
                unsafe { d.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        self.set_name(vk::ObjectType::BUFFER, ash::vk::Handle::as_raw(raw), name);
        Ok(Buffer {
            shared: self.shared.clone(),
            raw,
            allocation: Some(allocation),
            size,
            usage,
            owned: true,
        })
    }

    /// Creates a buffer in `CpuToGpu` memory filled with `data`.
    pub fn create_buffer_init(
        &self,
        name: &str,
        data: &[u8],
        usage: BufferUsage,
    ) -> Result<Buffer> {
        let mut b = self.create_buffer(name, data.len() as u64, usage, MemoryLocation::CpuToGpu)?;
        b.write(0, data)?;
        Ok(b)
    }

    /// Creates an image (2D, or 2D array when `layers > 1`), checked against the device limits.
    pub fn create_image(&self, desc: &ImageDesc<'_>) -> Result<Image> {
        let caps = &self.shared.caps;
        if desc.width == 0 || desc.height == 0 || desc.layers == 0 {
            return Err(RhiError::InvalidArgument(format!(
                "image {} has a zero dimension",
                desc.name
            )));
        }
        for (what, value, limit) in [
            ("width", desc.width, caps.max_image_dimension_2d),
            ("height", desc.height, caps.max_image_dimension_2d),
            ("layers", desc.layers, caps.max_image_array_layers),
        ] {
            if value > limit {
                return Err(RhiError::Limit {
                    what: format!("image {} {what}", desc.name),
                    value: value.into(),
                    limit: limit.into(),
                });
            }
        }
        let d = &self.shared.device;
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format.to_vk())
            .extent(vk::Extent3D {
                width: desc.width,
                height: desc.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(desc.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(image_usage_to_vk(desc.usage))
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info; destroyed in Drop or below on failure.
        let raw = unsafe { d.create_image(&info, None) }.call("vkCreateImage")?;
        // SAFETY: `raw` is a live image of this device.
        let requirements = unsafe { d.get_image_memory_requirements(raw) };
        let allocation = self
            .allocate(desc.name, requirements, MemoryLocation::GpuOnly, false)
            .and_then(|a| {
                // SAFETY: the allocation satisfies `requirements`.
                match unsafe { d.bind_image_memory(raw, a.memory(), a.offset()) } {
                    Ok(()) => Ok(a),
                    Err(result) => {
                        free_allocation(&self.shared, a);
                        Err(RhiError::Vulkan {
                            call: "vkBindImageMemory",
                            result,
                        })
                    }
                }
            });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `raw` is unused.
                unsafe { d.destroy_image(raw, None) };
                return Err(e);
            }
        };
        // SAFETY: `raw` is bound to memory; the view is destroyed before the image.
        let view = match unsafe { self.create_view(raw, desc, 0) } {
            Ok(v) => v,
            Err(e) => {
                // SAFETY: `raw` is unused; the allocation is returned to the allocator.
                unsafe { d.destroy_image(raw, None) };
                free_allocation(&self.shared, allocation);
                return Err(e);
            }
        };
        self.set_name(
            vk::ObjectType::IMAGE,
            ash::vk::Handle::as_raw(raw),
            desc.name,
        );
        Ok(Image {
            shared: self.shared.clone(),
            raw,
            view,
            allocation: Some(allocation),
            format: desc.format,
            width: desc.width,
            height: desc.height,
            layers: desc.layers,
            base_layer: 0,
            usage: desc.usage,
            owned: true,
            keep_alive: None,
        })
    }

    /// Wraps an engine's `VkImage` (2D, one mip level, `desc.layers` layers, created with `desc.format` and
    /// at least `desc.usage`). Only a view is created; the image and its memory stay the engine's.
    ///
    /// # Safety
    /// `handle` must be a live `VkImage` of this device matching `desc`, outliving the returned `Image`.
    pub unsafe fn external_image(&self, handle: u64, desc: &ImageDesc<'_>) -> Result<Image> {
        if handle == 0 || desc.width == 0 || desc.height == 0 || desc.layers == 0 {
            return Err(RhiError::InvalidArgument(format!(
                "external image {} is null or empty",
                desc.name
            )));
        }
        // SAFETY: the caller guarantees `handle` is a live image of this device matching `desc`.
        unsafe { engine_image(&self.shared, ash::vk::Handle::from_raw(handle), desc, 0) }
    }

    /// Wraps array layer `layer` of an engine's `VkImage` as an image of one layer (`desc.layers` is 1):
    /// its view, barriers, clears and copies address that layer alone, so that a pass writes it directly.
    ///
    /// # Safety
    /// As for [`Device::external_image`]; the image has more than `layer` layers.
    pub unsafe fn external_image_layer(
        &self,
        handle: u64,
        desc: &ImageDesc<'_>,
        layer: u32,
    ) -> Result<Image> {
        if handle == 0 || desc.width == 0 || desc.height == 0 || desc.layers != 1 {
            return Err(RhiError::InvalidArgument(format!(
                "external image layer {} is null, empty or not one layer",
                desc.name
            )));
        }
        // SAFETY: the caller guarantees `handle` is a live image of this device with layer `layer`.
        unsafe { engine_image(&self.shared, ash::vk::Handle::from_raw(handle), desc, layer) }
    }

    /// Wraps an engine's `VkBuffer` of `size` bytes, to be used as `usage` says (a storage buffer must fit
    /// `maxStorageBufferRange`).
    ///
    /// # Safety
    /// `handle` must be a live `VkBuffer` of this device of at least `size` bytes, created with `usage`,
    /// outliving the result.
    pub unsafe fn external_buffer(
        &self,
        handle: u64,
        size: u64,
        usage: BufferUsage,
    ) -> Result<Buffer> {
        if handle == 0 || size == 0 {
            return Err(RhiError::InvalidArgument(
                "external buffer is null or empty".into(),
            ));
        }
        let limit = self.shared.caps.max_storage_buffer_range;
        if usage.contains(BufferUsage::STORAGE) && size > limit {
            return Err(RhiError::Limit {
                what: "external storage buffer".into(),
                value: size,
                limit,
            });
        }
        Ok(Buffer {
            shared: self.shared.clone(),
            raw: ash::vk::Handle::from_raw(handle),
            allocation: None,
            size,
            usage: buffer_usage_to_vk(usage),
            owned: false,
        })
    }

    /// A view over all layers when the usage allows one (sampled, storage or attachment), else null.
    ///
    /// # Safety
    /// `raw` must be a live image of this device created as `desc` says.
    unsafe fn create_view(
        &self,
        raw: vk::Image,
        desc: &ImageDesc<'_>,
        base_layer: u32,
    ) -> Result<vk::ImageView> {
        // SAFETY: guaranteed by the caller.
        unsafe { create_view(&self.shared, raw, desc, base_layer) }
    }

    fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Allocation> {
        let mut alloc = self
            .shared
            .allocator
            .lock()
            .map_err(|_| RhiError::Allocation {
                name: name.into(),
                message: "allocator mutex poisoned".into(),
            })?;
        alloc
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .inspect(|a| {
                LIVE_GPU_BYTES.fetch_add(a.size(), Ordering::SeqCst);
            })
            .map_err(|e| RhiError::Allocation {
                name: name.into(),
                message: e.to_string(),
            })
    }

    pub(crate) fn set_name(&self, ty: vk::ObjectType, handle: u64, name: &str) {
        let (Some(utils), Ok(cname)) = (&self.shared.debug_utils, std::ffi::CString::new(name))
        else {
            return;
        };
        let mut info = vk::DebugUtilsObjectNameInfoEXT::default().object_name(&cname);
        info.object_type = ty;
        info.object_handle = handle;
        // SAFETY: `handle` is a live object of type `ty` on this device; naming is advisory.
        let _ = unsafe { utils.set_debug_utils_object_name(&info) };
    }
}

/// An engine's image `raw` (not owned: never destroyed by its wrapper), `desc.layers` layers from
/// `base_layer`, with a view of its own.
///
/// # Safety
/// `raw` must be a live image of `shared`'s device created as `desc` says, with those layers, that outlives
/// every use of the wrapper.
unsafe fn engine_image(
    shared: &Arc<Shared>,
    raw: vk::Image,
    desc: &ImageDesc<'_>,
    base_layer: u32,
) -> Result<Image> {
    // SAFETY: guaranteed by the caller.
    let view = unsafe { create_view(shared, raw, desc, base_layer) }?;
    Ok(Image {
        shared: shared.clone(),
        raw,
        view,
        allocation: None,
        format: desc.format,
        width: desc.width,
        height: desc.height,
        layers: desc.layers,
        base_layer,
        usage: desc.usage,
        owned: false,
        keep_alive: None,
    })
}

/// A view of `desc.layers` layers of `raw` from `base_layer` (none for images no shader or attachment reads).
///
/// # Safety
/// `raw` must be a live image of `shared`'s device created as `desc` says, with those layers.
unsafe fn create_view(
    shared: &Shared,
    raw: vk::Image,
    desc: &ImageDesc<'_>,
    base_layer: u32,
) -> Result<vk::ImageView> {
    let viewable = ImageUsage::SAMPLED
        | ImageUsage::STORAGE
        | ImageUsage::COLOR_TARGET
        | ImageUsage::DEPTH_TARGET;
    if desc.usage.0 & viewable.0 == 0 {
        return Ok(vk::ImageView::null());
    }
    let view_type = if desc.layers > 1 {
        vk::ImageViewType::TYPE_2D_ARRAY
    } else {
        vk::ImageViewType::TYPE_2D
    };
    let view_info = vk::ImageViewCreateInfo::default()
        .image(raw)
        .view_type(view_type)
        .format(desc.format.to_vk())
        .subresource_range(
            subresource_range(desc.format, desc.layers)
                .aspect_mask(desc.format.view_aspect())
                .base_array_layer(base_layer),
        );
    // SAFETY: guaranteed by the caller.
    unsafe { shared.device.create_image_view(&view_info, None) }.call("vkCreateImageView")
}

pub(crate) fn subresource_range(format: Format, layers: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(format.aspect())
        .base_mip_level(0)
        .level_count(1)
        .base_array_layer(0)
        .layer_count(layers)
}

impl Buffer {
    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// The `VkBuffer` handle, for handing the buffer to a component that speaks raw Vulkan (a C ABI).
    pub fn raw_handle(&self) -> u64 {
        ash::vk::Handle::as_raw(self.raw)
    }

    /// The buffer's device address (it must have been created with `SHADER_DEVICE_ADDRESS` usage).
    pub(crate) fn device_address(&self) -> u64 {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.raw);
        // SAFETY: live buffer; the RHI only asks for addresses of buffers it created with
        // SHADER_DEVICE_ADDRESS usage on a device with bufferDeviceAddress enabled.
        unsafe { self.shared.device.get_buffer_device_address(&info) }
    }

    /// Writes `data` at `offset` into a host-visible buffer.
    pub fn write(&mut self, offset: u64, data: &[u8]) -> Result<()> {
        let size = self.size;
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| RhiError::InvalidArgument("buffer is not host-visible".into()))?;
        let end = offset
            .checked_add(data.len() as u64)
            .filter(|&e| e <= size)
            .ok_or_else(|| {
                RhiError::InvalidArgument(format!(
                    "write of {} bytes at {offset} exceeds {size}",
                    data.len()
                ))
            })?;
        slice[offset as usize..end as usize].copy_from_slice(data);
        Ok(())
    }

    /// Reads the `u64` at byte `offset` of a mapped buffer with a volatile load: for values the GPU may
    /// write at any moment (such as a completion marker polled without a fence), which [`Buffer::read`]'s
    /// slice must not alias.
    pub fn read_u64_volatile(&self, offset: u64) -> Result<u64> {
        let ptr = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_ptr())
            .ok_or_else(|| RhiError::InvalidArgument("buffer is not host-visible".into()))?
            .as_ptr()
            .cast::<u8>();
        let address = (ptr as usize).checked_add(offset as usize);
        if address.is_none_or(|a| !a.is_multiple_of(8))
            || offset.checked_add(8).is_none_or(|end| end > self.size)
        {
            return Err(RhiError::InvalidArgument(format!(
                "u64 read at offset {offset} of a {}-byte buffer",
                self.size
            )));
        }
        // SAFETY: the mapping covers `size` bytes and stays valid while `self` lives; the read is in
        // bounds and its address checked 8-aligned; a volatile load of a plain integer tolerates
        // concurrent device writes (it may see the old or the new value).
        Ok(unsafe { std::ptr::read_volatile(ptr.add(offset as usize).cast::<u64>()) })
    }

    /// The contents of a host-visible buffer (read after the GPU work that wrote it has completed).
    pub fn read(&self) -> Result<&[u8]> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..self.size as usize])
            .ok_or_else(|| RhiError::InvalidArgument("buffer is not host-visible".into()))
    }
}

impl Image {
    /// Texel format.
    pub fn format(&self) -> Format {
        self.format
    }
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Array layers.
    pub fn layers(&self) -> u32 {
        self.layers
    }
    /// The first array layer of the underlying `VkImage` this image is.
    pub fn base_layer(&self) -> u32 {
        self.base_layer
    }

    /// Another handle on an engine's image (wrapped by [`Device::external_image`] or
    /// [`Device::external_image_layer`], whose callers guarantee it outlives every use): its own view of the
    /// same layers. The plugin's own images cannot be aliased.
    pub fn alias(&self) -> Result<Image> {
        if self.owned {
            return Err(RhiError::InvalidArgument(
                "only an engine's image can be aliased".into(),
            ));
        }
        let desc = ImageDesc {
            name: "engine image",
            format: self.format,
            width: self.width,
            height: self.height,
            layers: self.layers,
            usage: self.usage,
        };
        // SAFETY: `self` wraps a live image of this device matching `desc` (its wrapper's contract).
        unsafe { engine_image(&self.shared, self.raw, &desc, self.base_layer) }
    }

    /// Another handle on an image of the plugin's own that several holders share: its own view of the
    /// same layers, which keeps `image` alive while it lives.
    pub fn alias_shared(image: &Arc<Image>) -> Result<Image> {
        let desc = ImageDesc {
            name: "shared image",
            format: image.format,
            width: image.width,
            height: image.height,
            layers: image.layers,
            usage: image.usage,
        };
        // SAFETY: `image` is a live image of this device matching `desc`; the alias holds it, so it
        // outlives every use of the alias.
        let mut alias = unsafe { engine_image(&image.shared, image.raw, &desc, image.base_layer) }?;
        alias.keep_alive = Some(Arc::clone(image));
        Ok(alias)
    }

    /// Declared usage.
    pub fn usage(&self) -> ImageUsage {
        self.usage
    }
    /// The `VkImage` handle, for handing the image to a component that speaks raw Vulkan (a C ABI).
    pub fn raw_handle(&self) -> u64 {
        ash::vk::Handle::as_raw(self.raw)
    }
    /// The `VkImageUsageFlags` the image was created with.
    pub fn raw_usage(&self) -> u32 {
        image_usage_to_vk(self.usage).as_raw()
    }
    /// Bytes needed to read back all layers tightly packed.
    pub fn byte_size(&self) -> u64 {
        u64::from(self.width)
            * u64::from(self.height)
            * u64::from(self.layers)
            * u64::from(self.format.texel_size())
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if self.owned {
            // SAFETY: callers wait for GPU work using this buffer before dropping it (submit_and_wait does).
            unsafe { self.shared.device.destroy_buffer(self.raw, None) };
        }
        if let Some(a) = self.allocation.take() {
            free_allocation(&self.shared, a);
        }
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: as for Buffer; the view is destroyed before its image, which is ours unless external.
        unsafe {
            if self.view != vk::ImageView::null() {
                self.shared.device.destroy_image_view(self.view, None);
            }
            if self.owned {
                self.shared.device.destroy_image(self.raw, None);
            }
        }
        if let Some(a) = self.allocation.take() {
            free_allocation(&self.shared, a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn usage_maps_to_vulkan() {
        let b = buffer_usage_to_vk(BufferUsage::STORAGE | BufferUsage::COPY_SRC);
        assert_eq!(
            b,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC
        );
        let i = image_usage_to_vk(ImageUsage::STORAGE | ImageUsage::SAMPLED);
        assert_eq!(
            i,
            vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED
        );
        assert_eq!(
            image_usage_to_vk(ImageUsage::default()),
            vk::ImageUsageFlags::empty()
        );
    }

    #[test]
    fn acceleration_structure_input_is_addressable_build_input() {
        let b =
            buffer_usage_to_vk(BufferUsage::STORAGE | BufferUsage::ACCELERATION_STRUCTURE_INPUT);
        assert_eq!(
            b,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
                | vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR
        );
    }
}
