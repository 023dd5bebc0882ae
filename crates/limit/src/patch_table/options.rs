//! What a patch table is built with: OpenSubdiv 3.5's `PatchTableFactory::Options`, and the
//! exact end caps no other library has.

use subd_mesh::choice::Choice;

/// How the patches around an irregular feature that isolation leaves behind (an
/// extraordinary vertex, an irregular sharp feature) are represented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EndCaps {
    /// A bilinear quad (a linear triangle for Loop) through the four (three) limit points
    /// of the corners (`ENDCAP_BILINEAR_BASIS`).
    Bilinear,
    /// A regular B-spline (box-spline for Loop) patch fitted to the irregular one
    /// (`ENDCAP_BSPLINE_BASIS`).
    BSpline,
    /// A Gregory patch: 20 points for a quad, 18 for a triangle (`ENDCAP_GREGORY_BASIS`),
    /// OpenSubdiv's default.
    #[default]
    #[serde(rename = "gregory")]
    GregoryBasis,
    /// The irregular patch evaluated exactly (Stam's eigenbasis, or local refinement next to
    /// irregular sharp features), so the table is the limit surface everywhere.
    Exact,
}

impl EndCaps {
    /// Every kind, in the order the command line lists them.
    pub const ALL: [EndCaps; 4] = {
        // Read off the one table of names, so the two lists cannot drift apart.
        let values = <EndCaps as Choice>::VALUES;
        assert!(values.len() == 4);
        let mut all = [EndCaps::GregoryBasis; 4];
        let mut i = 0;
        while i < all.len() {
            all[i] = values[i].0;
            i += 1;
        }
        all
    };

    /// The command-line name (`gregory`, `bspline`, `bilinear`, `exact`).
    pub fn name(self) -> &'static str {
        <Self as Choice>::name(self)
    }
}

impl Choice for EndCaps {
    const OPTION: &'static str = "end caps";
    const VALUES: &'static [(Self, &'static str, &'static str)] = &[
        (
            EndCaps::GregoryBasis,
            "gregory",
            "Gregory patches (20 points; Gregory triangles of 18 for Loop), OpenSubdiv's default",
        ),
        (
            EndCaps::BSpline,
            "bspline",
            "Regular B-spline (box-spline) patches fitted to the irregular ones",
        ),
        (
            EndCaps::Bilinear,
            "bilinear",
            "Bilinear quads (linear triangles) through the corners' limit points",
        ),
        (
            EndCaps::Exact,
            "exact",
            "The irregular patches evaluated exactly (subd's own)",
        ),
    ];
}

subd_mesh::choice_by_name!(EndCaps);

/// The deepest isolation level (OpenSubdiv's patch parameters hold 4 bits of depth and 10 of
/// u and v).
pub const MAX_ISOLATION: u8 = 10;

/// Options of a patch table, with OpenSubdiv 3.5's defaults
/// (`Far::PatchTableFactory::Options`): isolation 10, Gregory basis end caps, legacy sharp
/// corner patches on, single-crease and infinitely sharp patches off.
///
/// ```
/// use subd_limit::patches::{EndCaps, PatchOptions};
/// let o = PatchOptions::default();
/// assert_eq!((o.isolation, o.end_caps), (10, EndCaps::GregoryBasis));
/// assert!(o.legacy_sharp_corners && !o.single_crease && !o.inf_sharp);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub struct PatchOptions {
    /// Levels of feature-adaptive refinement around irregular features, 1 to
    /// [`MAX_ISOLATION`].
    pub isolation: u8,
    /// How the irregular patches left at the isolation level are represented.
    pub end_caps: EndCaps,
    /// Regular patches along a single semi-sharp crease stop isolating it
    /// (`useSingleCreasePatch`): the crease is evaluated with the patch's sharpness.
    pub single_crease: bool,
    /// Infinitely sharp features of regular topology become regular patches with boundary
    /// masks (`useInfSharpPatch`) instead of being isolated to the last level.
    pub inf_sharp: bool,
    /// A smooth corner (a boundary vertex with one face under edge-only interpolation)
    /// gets a sharp-corner regular patch, as OpenSubdiv did before 3.5
    /// (`generateLegacySharpCornerPatches`).
    pub legacy_sharp_corners: bool,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            isolation: MAX_ISOLATION,
            end_caps: EndCaps::GregoryBasis,
            single_crease: false,
            inf_sharp: false,
            legacy_sharp_corners: true,
        }
    }
}

impl PatchOptions {
    /// The cheapest table that is the exact limit everywhere, what tessellation takes by
    /// default: exact end caps one level from the base (most of the surface in regular
    /// patches, each irregular corner's quarter of a face exact), and infinitely sharp
    /// edges as the boundaries of regular patches (along a regular crease the limit is the
    /// boundary surface on each side, so those patches are exact; irregular crease and
    /// corner vertices still get exact caps).
    ///
    /// ```
    /// use subd_limit::patches::{EndCaps, PatchOptions};
    ///
    /// let o = PatchOptions::exact_limit();
    /// assert_eq!((o.isolation, o.end_caps, o.inf_sharp), (1, EndCaps::Exact, true));
    /// ```
    pub fn exact_limit() -> PatchOptions {
        PatchOptions {
            isolation: 1,
            end_caps: EndCaps::Exact,
            single_crease: false,
            inf_sharp: true,
            legacy_sharp_corners: false,
        }
    }
}
