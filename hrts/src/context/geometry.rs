//! Geometry setters: the engine's meshes (CPU arrays or Vulkan buffers) and the transforms of their
//! draws, taken into the context (checked and kept by [`crate::geometry`]).

use super::Context;
use crate::convert::finite;
use crate::error::{ApiError, ApiResult};
use crate::geometry::{cpu_geometry, vulkan_geometry};
use crate::types::*;

impl Context {
    pub(crate) fn set_geometry_cpu(&mut self, g: &HrtsCpuGeometry) -> ApiResult<()> {
        self.geometry = Some(cpu_geometry(g)?);
        self.retire_built();
        Ok(())
    }

    /// Sets the engine's meshes: one (`listed` false: `hrts_set_geometry_vulkan`) or a list whose
    /// messages name the mesh.
    pub(crate) fn set_geometry_vulkan(
        &mut self,
        meshes: &[HrtsVulkanGeometry],
        listed: bool,
    ) -> ApiResult<()> {
        self.geometry = Some(vulkan_geometry(&self.device, meshes, listed)?);
        self.retire_built();
        Ok(())
    }

    /// Moves the geometry's draws: `transforms` holds 16 floats (column-major) per draw, over all meshes in
    /// order. Everything is checked before anything changes.
    pub(crate) fn set_draw_transforms(&mut self, transforms: &[f32]) -> ApiResult<()> {
        finite(transforms, "transforms")?;
        let models: Vec<glam::Mat4> = transforms
            .chunks_exact(16)
            .map(glam::Mat4::from_cols_slice)
            .collect();
        let geometry = self.geometry.as_mut().ok_or_else(|| {
            ApiError::new(
                HrtsResult::ErrorInvalidState,
                "set the geometry before moving its draws",
            )
        })?;
        let moved = geometry.moved(&models)?;
        if let Some(built) = &self.built {
            built.shared.set_transforms(&moved.stored_to_world)?;
        }
        geometry.move_draws(moved);
        Ok(())
    }
}
