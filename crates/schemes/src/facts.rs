//! [`SchemeFacts`]: what a scheme is and what subd can do with it, declared once by the
//! scheme's rule file and read by [`Scheme`](crate::Scheme), the command line and Python
//! (their choices and messages come from here, not from lists of their own).

use std::fmt;

/// The faces a scheme takes as input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FaceKind {
    /// Any polygons.
    Any,
    /// Triangles only.
    Triangles,
    /// Quads only.
    Quads,
}

/// How one step of a scheme splits the faces of its parent level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Split {
    /// An n-gon into n quads around a face point (Catmull-Clark, Bilinear, two-phase).
    Quad,
    /// A triangle into four at its edge midpoints (Loop, the butterflies).
    Triangle,
    /// A triangle into three around its centroid, then every old edge flipped (√3).
    Sqrt3,
    /// The dual split: a face per face, edge and vertex of the parent (Doo-Sabin).
    Dual,
}

/// Which tags (and face-varying layouts) a scheme has rules for. A scheme refuses a mesh
/// that carries a tag it has no rule for, naming the element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TagSupport {
    /// Semi-sharp creases (finite sharpness decaying level by level).
    pub semi_sharp_creases: bool,
    /// Infinitely sharp creases.
    pub infinite_creases: bool,
    /// Corner (vertex sharpness) tags.
    pub corners: bool,
    /// Hole faces.
    pub holes: bool,
    /// Non-manifold edges and vertices.
    pub non_manifold: bool,
    /// OpenSubdiv's six face-varying interpolation modes (the others refine face-varying
    /// data as a mesh of values: see [`Self::uv_seams`]).
    pub fvar_modes: bool,
    /// Face-varying data with seams (texture coordinates that differ across an edge).
    pub uv_seams: bool,
}

/// What subd computes for a scheme, beyond refining it (which every scheme has).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Capability {
    /// Uniform refinement (`Refinement`, `subd refine`).
    Refine,
    /// Limit positions of a level's vertices (`subd limit`, `refine --limit`): a limit
    /// surface other than the mesh itself.
    Limit,
    /// Exact evaluation at any (face, u, v): patch tables, `subd eval`, `subd tessellate`.
    Evaluate,
    /// Progressive interpolation (`subd pia`).
    Interpolate,
    /// Editing and deforming the limit surface under constraints (`subd edit`, `subd deform`).
    Edit,
    /// Adaptive refinement (`subd adaptive`).
    Adaptive,
    /// The local subdivision matrix at a valence (`subd analyze --surface`): one mask for
    /// every vertex of a valence (so not the two-phase scheme, whose λ varies per vertex).
    Analyse,
}

impl Capability {
    /// Every capability, in the order the documentation lists them.
    pub const ALL: [Capability; 7] = [
        Capability::Refine,
        Capability::Limit,
        Capability::Evaluate,
        Capability::Interpolate,
        Capability::Edit,
        Capability::Adaptive,
        Capability::Analyse,
    ];

    /// What the capability is, as a message names it ("editing needs catmull-clark or
    /// loop").
    pub fn gerund(self) -> &'static str {
        match self {
            Capability::Refine => "refining",
            Capability::Limit => "a limit surface",
            Capability::Evaluate => "exact evaluation",
            Capability::Interpolate => "progressive interpolation",
            Capability::Edit => "editing",
            Capability::Adaptive => "adaptive refinement",
            Capability::Analyse => "mask analysis",
        }
    }
}

impl fmt::Display for Capability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.gerund())
    }
}

/// One scheme's facts. Each rule file declares its scheme's as a `const` (`FACTS`);
/// [`crate::Scheme::facts`] finds them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SchemeFacts {
    /// The name the command line and files use (without parameters).
    pub name: &'static str,
    /// One line: who the scheme is by, the faces it takes, its parameter.
    pub summary: &'static str,
    /// The faces it takes.
    pub input_faces: FaceKind,
    /// How one step splits the faces.
    pub split: Split,
    /// Whether every level's vertices stay on the limit surface.
    pub interpolating: bool,
    /// Whether it refines with OpenSubdiv's topology, order and options (OpenSubdiv's
    /// three and the two-phase scheme).
    pub opensubdiv_family: bool,
    /// The tags it has rules for.
    pub tags: TagSupport,
    /// Bytes per output vertex at the peak of refining and writing: held, and streamed
    /// from the level above where the scheme streams (see
    /// [`crate::Scheme::peak_bytes_per_vertex`]).
    pub peak_bytes_per_vertex: (u64, Option<u64>),
    /// What subd computes for it.
    pub capabilities: &'static [Capability],
}

/// The tags OpenSubdiv's schemes have rules for: all of them.
pub(crate) const OPENSUBDIV_TAGS: TagSupport = TagSupport {
    semi_sharp_creases: true,
    infinite_creases: true,
    corners: true,
    holes: true,
    non_manifold: true,
    fvar_modes: true,
    uv_seams: true,
};

/// The tags the split schemes share: infinitely sharp creases and corners, no more.
pub(crate) const SPLIT_TAGS: TagSupport = TagSupport {
    semi_sharp_creases: false,
    infinite_creases: true,
    corners: true,
    holes: false,
    non_manifold: false,
    fvar_modes: false,
    uv_seams: false,
};
