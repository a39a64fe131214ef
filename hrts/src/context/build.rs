//! Building the passes: the geometry and engine images shared by all lights, each light's passes, and
//! the frame bookkeeping that says when they may be used or dropped.

use super::{Built, Context, FrameProgress, LightPasses};
use crate::error::{invalid, ApiError, ApiResult};
use crate::geometry::geometry_from;
use crate::types::*;
use passes::retire::completed_before;
use passes::{MinCombine, ShadowInputs, ShadowPipeline, SharedGeometry};
use rhi::{Format, Image, ImageDesc, ImageUsage};

impl Context {
    /// Builds what a configuration, geometry or targets call retired: everything, or the lights
    /// reconfigured.
    pub(crate) fn ensure_built(&mut self) -> ApiResult<&mut Built> {
        if self.built.is_none() {
            self.built = Some(self.build_shared()?);
        }
        let (device, lights, builds) = (&self.device, &self.lights, &mut self.light_builds);
        let built = self
            .built
            .as_mut()
            .ok_or_else(|| ApiError::new(HrtsResult::ErrorInternal, "passes not built"))?;
        for (i, ((slot, config), &shape)) in built
            .lights
            .iter_mut()
            .zip(lights)
            .zip(&self.frusta)
            .enumerate()
        {
            if slot.is_none() {
                let config = shape.config(config);
                // The light's layer, written directly unless the configuration reads the final output
                // back (from the pipeline's own image).
                let read_back = config
                    .extra_outputs
                    .contains(config.plan_request().final_output());
                let layer = built.output_layers.get(i).filter(|_| !read_back);
                let passes = (|| -> Result<LightPasses, passes::PassError> {
                    let inputs = ShadowInputs {
                        depth: &built.depth,
                        normal: &built.normal,
                        surface: built.surface,
                        direct_output: layer.filter(|_| shape.frusta == 1),
                        scratch_set: 0,
                    };
                    // The frusta of the context's lights, in recording order, take the scratch sets in
                    // turn: neighbours' lists can then be built side by side (`passes::ListBatch`). Sized
                    // lights' maps all take the first set: their pair lists run to hundreds of MiB and
                    // their ray traces, not their builds, take their time.
                    let first_frustum: usize = self.frusta[..i].iter().map(|s| s.frusta).sum();
                    let sized = config.mode == passes::ShadowMode::Area;
                    let frusta = (0..shape.frusta)
                        .map(|f| {
                            ShadowPipeline::with_shared_geometry(
                                device,
                                built.shared.clone(),
                                &ShadowInputs {
                                    scratch_set: if sized { 0 } else { first_frustum + f },
                                    ..inputs
                                },
                                config,
                            )
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    let combine = if frusta.len() > 1 {
                        let outputs: Vec<&Image> = frusta.iter().map(|p| p.output()).collect();
                        let output = layer.map(Image::alias).transpose()?;
                        Some(MinCombine::new(device, &outputs, output)?)
                    } else {
                        None
                    };
                    Ok(LightPasses {
                        frusta,
                        combine,
                        direct: layer.is_some(),
                    })
                })()
                .map_err(|e| {
                    let e = ApiError::from(e);
                    ApiError {
                        message: format!("light {i}: {}", e.message),
                        ..e
                    }
                })?;
                *slot = Some(passes);
                builds[i] += 1;
            }
        }
        Ok(built)
    }

    /// The geometry and engine images, with no light's passes yet.
    fn build_shared(&self) -> ApiResult<Built> {
        let (Some(source), Some(t)) = (self.geometry.as_ref(), self.targets) else {
            return Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "set geometry and targets before recording",
            ));
        };
        let device = &self.device;
        let geometry = geometry_from(device, source)?;
        let dynamic = self.lights.iter().any(|c| !c.static_geometry);
        let shared = SharedGeometry::new(device, geometry, dynamic)?;
        let wrap = |name, handle, format, usage, layers| {
            let desc = ImageDesc {
                name,
                format,
                width: t.width,
                height: t.height,
                layers,
                usage,
            };
            // SAFETY: the engine guarantees its images are live and match the description (contract).
            unsafe { device.external_image(handle, &desc) }
        };
        let direct = [Format::R32Float, Format::R16Float, Format::R8Unorm]
            .contains(&t.output_format)
            && t.output_usage.contains(ImageUsage::STORAGE)
            && device.can_store(t.output_format);
        let output_layers = if direct {
            (0..t.output_layers)
                .map(|layer| {
                    let desc = ImageDesc {
                        name: "engine visibility layer",
                        format: t.output_format,
                        width: t.width,
                        height: t.height,
                        layers: 1,
                        usage: ImageUsage::STORAGE | ImageUsage::COPY_DST,
                    };
                    // SAFETY: the engine guarantees its output is live, of its stated format (R32_SFLOAT,
                    // R16_SFLOAT or R8_UNORM) with storage usage, of `output_layers` layers (contract; checked
                    // against its stated usage and format).
                    unsafe { device.external_image_layer(t.output, &desc, layer) }
                })
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        Ok(Built {
            output_layers,
            lights: (0..self.lights.len()).map(|_| None).collect(),
            shared,
            depth: wrap(
                "engine depth",
                t.depth,
                t.depth_format,
                ImageUsage::SAMPLED,
                1,
            )?,
            normal: match t.normal {
                Some(handle) => wrap(
                    "engine normal",
                    handle,
                    t.normal_format,
                    ImageUsage::SAMPLED,
                    1,
                )?,
                // Normals derived from depth: an image of the plugin's own is bound, never read.
                None => device.create_image(&ImageDesc {
                    name: "normal (derived from depth; not read)",
                    format: Format::Rgba32Float,
                    width: 1,
                    height: 1,
                    layers: 1,
                    usage: ImageUsage::SAMPLED,
                })?,
            },
            engine_normal: t.normal.is_some(),
            surface: t.surface,
            output: wrap(
                "engine visibility",
                t.output,
                t.output_format,
                ImageUsage::COPY_DST,
                t.output_layers,
            )?,
        })
    }

    /// Starts frame `index`: checks that it follows the last one, and drops what only completed frames
    /// used.
    pub(crate) fn begin_frame(&mut self, index: u64) -> ApiResult<()> {
        if let Some(last) = self.last_frame.filter(|&last| index <= last) {
            return Err(invalid(format!(
                "frame_index {index} must be greater than the last frame's ({last})"
            )));
        }
        self.retired
            .release_completed(completed_before(index, self.frames_in_flight));
        Ok(())
    }

    /// The passes, once a frame was recorded to its end and no other is being recorded.
    pub(crate) fn finished_frame(&self) -> ApiResult<&Built> {
        match (&self.built, &self.progress) {
            (
                Some(built),
                FrameProgress {
                    open: None,
                    completed: Some(_),
                },
            ) => Ok(built),
            (_, FrameProgress { open: Some(_), .. }) => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "a frame is being recorded: record its remaining passes through HRTS_PASS_OUTPUT_COPY first",
            )),
            _ => Err(ApiError::new(
                HrtsResult::ErrorInvalidState,
                "no frame has been recorded to its end since the last configuration, geometry or targets call",
            )),
        }
    }
}
