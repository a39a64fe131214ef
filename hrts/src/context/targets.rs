//! Targets: the engine's depth, normal and output images, checked against the device and kept as a
//! [`TargetSource`] for the passes.

use super::{Context, TargetSource};
use crate::convert::{require_usage, surface_input};
use crate::error::{invalid, ApiError, ApiResult};
use crate::types::*;
use passes::NormalEncoding;
use rhi::{Format, ImageUsage};

impl Context {
    pub(crate) fn set_targets(&mut self, t: &HrtsTargets) -> ApiResult<()> {
        let surface = surface_input(t)?;
        let derived = surface.encoding == NormalEncoding::FromDepth;
        if t.depth_image == 0 || (t.normal_image == 0 && !derived) || t.output_image == 0 {
            return Err(ApiError::new(
                HrtsResult::ErrorNullPointer,
                "depth_image, normal_image (unless normal_encoding is NONE) and output_image must be non-NULL",
            ));
        }
        let caps = self.device.capabilities();
        let max = caps.max_image_dimension_2d;
        if t.width == 0 || t.height == 0 || t.width > max || t.height > max {
            return Err(invalid(format!(
                "target size {}x{} must be within 1..={max}",
                t.width, t.height
            )));
        }
        if t.output_layers == 0 || t.output_layers > caps.max_image_array_layers {
            return Err(invalid(format!(
                "output_layers {} must be within 1..={}",
                t.output_layers, caps.max_image_array_layers
            )));
        }
        let view_z = [Format::R32Float, Format::R16Float];
        let depth_format = match t.depth_format {
            0 => Format::D32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(|raw| {
                    Format::depth_from_raw_vk(raw)
                        .or_else(|| view_z.into_iter().find(|f| f.raw_vk() == raw))
                })
                .ok_or_else(|| {
                    let accepted: Vec<String> = Format::DEPTH
                        .iter()
                        .chain(&view_z)
                        .map(|f| f.raw_vk().to_string())
                        .collect();
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "depth_format {raw} is not a depth format the plugin reads: one of {} (D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT, D32_SFLOAT_S8_UINT, or view Z in R32_SFLOAT, R16_SFLOAT), or 0 for D32_SFLOAT",
                            accepted.join(", ")
                        ),
                    )
                })?,
        };
        if derived && view_z.contains(&depth_format) {
            return Err(invalid(format!(
                "normal_encoding NONE derives normals from the projection's depth; depth_format {} is a view-Z image: give the engine's normals",
                depth_format.raw_vk()
            )));
        }
        if !self.device.can_sample(depth_format) {
            return Err(ApiError::new(
                HrtsResult::ErrorUnsupported,
                format!(
                    "the device cannot sample depth_format {} ({depth_format:?}) with optimal tiling",
                    depth_format.raw_vk()
                ),
            ));
        }
        let output_format = match t.output_format {
            0 => Format::R32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(Format::visibility_from_raw_vk)
                .ok_or_else(|| {
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "output_format {raw} is not a visibility format the plugin writes: R8_UNORM (9), R16_SFLOAT (76) or R32_SFLOAT (100), or 0 for R32_SFLOAT"
                        ),
                    )
                })?,
        };
        if output_format != Format::R32Float
            && !self.device.can_blit(Format::R32Float, output_format)
        {
            return Err(ApiError::new(
                HrtsResult::ErrorUnsupported,
                format!(
                    "the device cannot blit R32_SFLOAT into output_format {} ({output_format:?})",
                    output_format.raw_vk()
                ),
            ));
        }
        require_usage(t.depth_usage, ImageUsage::SAMPLED, "depth_image", "SAMPLED")?;
        let normal_format = match t.normal_format {
            0 => Format::Rgba32Float,
            raw => i32::try_from(raw)
                .ok()
                .and_then(Format::normal_from_raw_vk)
                .ok_or_else(|| {
                    ApiError::new(
                        HrtsResult::ErrorInvalidEnum,
                        format!(
                            "normal_format {raw} is not a normal format the plugin reads: R32G32B32A32_SFLOAT, R16G16B16A16_SFLOAT, A2B10G10R10_UNORM_PACK32, R8G8B8A8_UNORM, R16G16_SNORM, R16G16_UNORM or R16G16_SFLOAT, or 0 for R32G32B32A32_SFLOAT"
                        ),
                    )
                })?,
        };
        if !derived {
            if !surface.accepts(normal_format) {
                return Err(invalid(format!(
                    "normal_format {} ({normal_format:?}, {} channels) cannot hold {:?} normals: xyz needs four channels",
                    normal_format.raw_vk(),
                    normal_format.channels(),
                    surface.encoding
                )));
            }
            if !self.device.can_sample(normal_format) {
                return Err(ApiError::new(
                    HrtsResult::ErrorUnsupported,
                    format!(
                        "the device cannot sample normal_format {} ({normal_format:?})",
                        normal_format.raw_vk()
                    ),
                ));
            }
            require_usage(
                t.normal_usage,
                ImageUsage::SAMPLED,
                "normal_image",
                "SAMPLED",
            )?;
        }
        let output_usage = require_usage(
            t.output_usage,
            ImageUsage::COPY_DST,
            "output_image",
            "TRANSFER_DST",
        )?;
        self.targets = Some(TargetSource {
            width: t.width,
            height: t.height,
            depth: t.depth_image,
            depth_format,
            output_format,
            normal: (!derived).then_some(t.normal_image),
            normal_format,
            surface,
            output: t.output_image,
            output_layers: t.output_layers,
            output_usage,
        });
        self.retire_built();
        Ok(())
    }
}
