//! The C enumerations under their Rust names, the sets of passes and resources, and how the safe API
//! reads the enumeration values the plugin writes into its structs.

use super::error::{Error, Result};
use crate::types::*;

pub use crate::types::{
    HrtsBinningPath as BinningPath, HrtsFaces as Faces, HrtsIndexType as IndexType,
    HrtsLightDecision as LightDecision, HrtsNormalEncoding as NormalEncoding,
    HrtsNormalSpace as NormalSpace, HrtsPass as Pass, HrtsPassStatus as PassStatus,
    HrtsPenumbraFilter as PenumbraFilter, HrtsResource as Resource, HrtsShadowMode as ShadowMode,
};

impl Pass {
    /// The pass's name, as frame reports and logs give it ("ray trace", "FXAA", ..., "output copy").
    pub fn name(self) -> &'static str {
        match crate::convert::pass_from_index(self as u32) {
            Some(pass) => pass.name(),
            // The context's own pass, after the pipelines'.
            None => "output copy",
        }
    }
}

impl Resource {
    /// The resource's name, as frame reports and logs give it ("prim list entries", "rt visibility", ...).
    pub fn name(self) -> &'static str {
        crate::convert::RESOURCES[self as usize].name()
    }
}

impl ShadowMode {
    /// "none", "hard", "soft", "hybrid", "area" or "auto".
    pub fn name(self) -> &'static str {
        crate::convert::mode_from_c(self).name()
    }

    /// Whether the mode traces shadow rays through the primitive map (hard, hybrid and area, and so
    /// auto).
    pub fn traces_rays(self) -> bool {
        crate::convert::mode_from_c(self).traces_rays()
    }
}

impl PassStatus {
    /// Why a pass that did not run was skipped, in words (`None` for [`PassStatus::Ran`]).
    pub fn reason(self) -> Option<&'static str> {
        use passes::SkipReason as R;
        let skipped = match self {
            Self::Ran => return None,
            Self::NotInPlan => R::NotRequested,
            Self::UpToDate => R::UpToDate,
            Self::Shared => R::Shared,
            Self::Culled => R::Culled,
        };
        Some(skipped.describe())
    }

    /// The status as the C enumeration names it, without its prefix: "RAN", "UP_TO_DATE", "SHARED",
    /// "NOT_IN_PLAN" or "CULLED".
    pub fn name(self) -> &'static str {
        match self {
            Self::Ran => "RAN",
            Self::UpToDate => "UP_TO_DATE",
            Self::Shared => "SHARED",
            Self::NotInPlan => "NOT_IN_PLAN",
            Self::Culled => "CULLED",
        }
    }
}

impl BinningPath {
    /// "compute", "hardware", "software", "hardware (tier-1 emulation)" or, in a request, "auto".
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Compute => "compute",
            Self::Hardware => "hardware",
            Self::Software => "software",
            Self::EmulatedTier1 => "hardware (tier-1 emulation)",
        }
    }
}

/// A C enumeration whose values are 0, 1, 2, ... in the order of [`CEnum::ALL`].
pub(crate) trait CEnum: Copy + 'static {
    /// Every value, in value order.
    const ALL: &'static [Self];
    /// The C type's name, for messages.
    const C_NAME: &'static str;
    /// The C value.
    #[cfg(test)]
    fn value(self) -> u32;
}

macro_rules! c_enums {
    ($($name:ident [$($variant:ident),* $(,)?];)*) => {$(
        impl CEnum for $name {
            const ALL: &'static [Self] = &[$(Self::$variant),*];
            const C_NAME: &'static str = stringify!($name);
            #[cfg(test)]
            fn value(self) -> u32 {
                self as u32
            }
        }
    )*};
}

c_enums! {
    HrtsShadowMode [None, Hard, Soft, Hybrid, Area, Auto];
    HrtsFaces [Both, FrontOnly];
    HrtsBinningPath [Auto, Hardware, Software, EmulatedTier1, Compute];
    HrtsPenumbraFilter [Shrinking, Standard];
    HrtsPass [
        PrimBuffer, ShadowMap, PrimitiveMap, Occupancy, RayTrace, ShadowMapTest, Pcss, Fxaa, LerpFactor,
        Blend, FillLit, OutputCopy,
    ];
    HrtsPassStatus [NotInPlan, Ran, UpToDate, Shared, Culled];
    HrtsLightDecision [Shadowed, OutOfView];
    HrtsResource [
        ShadowMap, PrimListOffsets, PrimListEntries, Occupancy, RtVisibility, BlockerDistance,
        ShadowMapVisibility, Pcss, RtAntialiased, LerpFactor, Hybrid, Lit,
    ];
}

/// The enumeration value `value` of field `field`, which `call` wrote.
pub(crate) fn decode<T: CEnum>(call: &'static str, field: &str, value: u32) -> Result<T> {
    T::ALL.get(value as usize).copied().ok_or_else(|| {
        Error::new(
            call,
            HrtsResult::ErrorInvalidEnum,
            format!("{field} is {value}, which names no {}", T::C_NAME),
        )
    })
}

/// A set of [`Resource`]s: bit `1 << resource`, as `HrtsConfig::extra_outputs` holds them.
///
/// ```
/// use hrts::{Resource, ResourceSet};
///
/// let set = ResourceSet::EMPTY.with(Resource::BlockerDistance).with(Resource::Pcss);
/// assert!(set.contains(Resource::Pcss) && !set.contains(Resource::Hybrid));
/// assert_eq!(set.iter().collect::<Vec<_>>(), [Resource::BlockerDistance, Resource::Pcss]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct ResourceSet(u32);

impl ResourceSet {
    /// No resource.
    pub const EMPTY: Self = Self(0);

    /// The set with `resource` added.
    pub fn with(self, resource: Resource) -> Self {
        Self(self.0 | 1 << resource as u32)
    }

    /// Whether the set holds `resource`.
    pub fn contains(self, resource: Resource) -> bool {
        self.0 & 1 << resource as u32 != 0
    }

    /// The resources of the set, in value order.
    pub fn iter(self) -> impl Iterator<Item = Resource> {
        Resource::ALL
            .iter()
            .copied()
            .filter(move |&r| self.contains(r))
    }

    /// The C bits (`HrtsConfig::extra_outputs`).
    pub(crate) fn bits(self) -> u32 {
        self.0
    }

    /// The set of C bits, all of which name resources.
    pub(crate) fn from_bits(call: &'static str, field: &str, bits: u32) -> Result<Self> {
        if bits >> HRTS_RESOURCE_COUNT != 0 {
            return Err(Error::new(
                call,
                HrtsResult::ErrorInvalidEnum,
                format!("{field} 0x{bits:x} has bits of no HrtsResource"),
            ));
        }
        Ok(Self(bits))
    }
}

impl FromIterator<Resource> for ResourceSet {
    fn from_iter<I: IntoIterator<Item = Resource>>(resources: I) -> Self {
        resources.into_iter().fold(Self::EMPTY, Self::with)
    }
}

/// A set of [`Pass`]es to record (bit `1 << pass`): see
/// [`Context::record_passes`](crate::Context::record_passes).
///
/// ```
/// use hrts::{Pass, PassMask};
///
/// assert!(PassMask::LIGHT_SPACE.contains(Pass::ShadowMap));
/// assert!(PassMask::SCREEN_SPACE.contains(Pass::RayTrace));
/// assert_eq!(PassMask::LIGHT_SPACE.union(PassMask::SCREEN_SPACE), PassMask::ALL);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PassMask(u32);

impl PassMask {
    /// The light-space passes, which read neither depth nor normal (`HRTS_PASS_MASK_LIGHT_SPACE`): record
    /// them before the engine's depth pass.
    pub const LIGHT_SPACE: Self = Self(HRTS_PASS_MASK_LIGHT_SPACE);
    /// The passes that read the engine's depth and normal, and the output copy
    /// (`HRTS_PASS_MASK_SCREEN_SPACE`): record them after the engine's G-buffer.
    pub const SCREEN_SPACE: Self = Self(HRTS_PASS_MASK_SCREEN_SPACE);
    /// Every pass (`HRTS_PASS_MASK_ALL`).
    pub const ALL: Self = Self(HRTS_PASS_MASK_ALL);

    /// The passes of both masks.
    pub fn union(self, other: Self) -> Self {
        Self(self.0 | other.0)
    }

    /// Whether the mask holds `pass`.
    pub fn contains(self, pass: Pass) -> bool {
        self.0 & 1 << pass as u32 != 0
    }

    /// The passes of the mask, in recording order.
    pub fn iter(self) -> impl Iterator<Item = Pass> {
        Pass::ALL.iter().copied().filter(move |&p| self.contains(p))
    }

    /// The mask of C bits, all of which name passes.
    pub(crate) fn from_bits(call: &'static str, field: &str, bits: u32) -> Result<Self> {
        if bits & !HRTS_PASS_MASK_ALL != 0 {
            return Err(Error::new(
                call,
                HrtsResult::ErrorInvalidEnum,
                format!("{field} 0x{bits:x} has bits of no HrtsPass"),
            ));
        }
        Ok(Self(bits))
    }

    /// The C bits.
    pub(crate) fn bits(self) -> u32 {
        self.0
    }
}

impl From<Pass> for PassMask {
    fn from(pass: Pass) -> Self {
        Self(1 << pass as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pass_and_resource_has_its_own_name() {
        let passes: std::collections::HashSet<&str> = Pass::ALL.iter().map(|p| p.name()).collect();
        assert_eq!(passes.len(), Pass::ALL.len());
        assert_eq!(Pass::RayTrace.name(), "ray trace");
        assert_eq!(Pass::OutputCopy.name(), "output copy");
        let resources: std::collections::HashSet<&str> =
            Resource::ALL.iter().map(|r| r.name()).collect();
        assert_eq!(resources.len(), Resource::ALL.len());
        assert_eq!(Resource::PrimListEntries.name(), "prim list entries");
    }

    #[test]
    fn pass_status_names_are_the_c_names() {
        let header = include_str!("../../include/hrts.h");
        for &status in PassStatus::ALL {
            let c = format!("HRTS_PASS_STATUS_{} = {},", status.name(), status as u32);
            assert!(header.contains(&c), "the header lacks {c}");
            assert_eq!(status.reason().is_none(), status == PassStatus::Ran);
        }
        assert_eq!(
            BinningPath::EmulatedTier1.name(),
            "hardware (tier-1 emulation)"
        );
    }

    fn values_are_indices<T: CEnum>() {
        for (i, v) in T::ALL.iter().enumerate() {
            assert_eq!(v.value() as usize, i, "{}", T::C_NAME);
        }
    }

    #[test]
    fn every_c_enum_lists_its_values_in_order() {
        values_are_indices::<HrtsShadowMode>();
        values_are_indices::<HrtsFaces>();
        values_are_indices::<HrtsBinningPath>();
        values_are_indices::<HrtsPenumbraFilter>();
        values_are_indices::<HrtsPass>();
        values_are_indices::<HrtsPassStatus>();
        values_are_indices::<HrtsLightDecision>();
        values_are_indices::<HrtsResource>();
        assert_eq!(HrtsPass::ALL.len(), HRTS_PASS_COUNT);
        assert_eq!(HrtsResource::ALL.len(), HRTS_RESOURCE_COUNT);
    }

    #[test]
    fn unknown_values_are_errors() {
        let e = decode::<HrtsFaces>("hrts_get_frame_report", "faces", 2).unwrap_err();
        assert_eq!(e.code(), HrtsResult::ErrorInvalidEnum);
        assert_eq!(e.message(), "faces is 2, which names no HrtsFaces");
        assert!(ResourceSet::from_bits("x", "extra_outputs", 1 << HRTS_RESOURCE_COUNT).is_err());
    }
}
