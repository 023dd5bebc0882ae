//! Patch tables: feature-adaptive refinement into patches, as OpenSubdiv's
//! `TopologyRefiner::RefineAdaptive` + `Far::PatchTableFactory` make them.
//!
//! A renderer or a GPU evaluator does not consume a refined mesh: it refines the topology
//! only around irregular features (extraordinary vertices, sharp features, boundaries,
//! non-quads), to an isolation level, and takes every face whose neighbourhood is regular as
//! a bicubic B-spline patch (Catmull-Clark) or quartic box-spline patch (Loop), and every face
//! still touching an irregular feature at the last level as an *end cap*. The table holds
//! flat arrays a shader reads as they are: per patch type, control-point indices into the
//! refined vertices of all levels followed by the local points, and packed
//! [`PatchParam`]s saying where each patch lies in its base face.
//!
//! The pieces, one way down: [`levels`](self) makes the sparse levels and decides, with the
//! vertex tags of `features`, which faces to refine; `classify` finds the patches and their
//! masks; [`PatchTable`] holds the arrays.
//!
//! ```
//! use subd_limit::eval::FaceParam;
//! use subd_limit::patches::{PatchOptions, PatchTable, PatchType};
//! use subd_mesh::{DVec3, TopologyBuilder};
//! use subd_schemes::{Options, Scheme};
//!
//! // A cube: eight valence-3 vertices, isolated two levels.
//! let faces = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4];
//! let cube = TopologyBuilder::new(8).build(&[4; 6], &faces).unwrap();
//! let corners: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
//!     .collect();
//! let options = PatchOptions { isolation: 2, ..Default::default() };
//! let table =
//!     PatchTable::new(&cube, &corners, &Scheme::CatmullClark, &Options::default(), &options)
//!         .unwrap();
//! let census = table.census();
//! // Every face touches a valence-3 vertex, and so does each of its four children: at
//! // depth 2 each child has three regular patches and one end cap at its corner.
//! assert_eq!(census.by_type[&PatchType::Regular], 6 * 4 * 3);
//! assert_eq!(census.by_type[&PatchType::GregoryBasis], 24);
//! // The centre of a face is the centre of a regular patch; by symmetry it lies on the
//! // face's axis.
//! let p = table.evaluate(FaceParam { face: 0, sub: 0, u: 0.5, v: 0.5 }).unwrap();
//! assert!((p.position.x - 0.5).abs() < 1e-15 && (p.position.y - 0.5).abs() < 1e-15);
//! ```

mod array;
mod assembly;
mod basis;
mod basis_polynomials;
mod batch_eval;
mod box_fit;
mod bspline_caps;
mod cap_grid;
mod classify;
mod end_caps;
mod exact_caps;
mod face_varying;
mod features;
mod gather;
mod grid;
mod grid_samples;
mod kind;
mod levels;
mod loop_caps;
mod map;
mod options;
mod param;
mod patch_eval;
mod table;
mod table_stencil;

pub use array::PatchArray;
pub use basis_polynomials::{BasisBlend, MONOMIALS, PatchBasisPolynomials};
pub use face_varying::{FVarPatches, FVarPatchesLayout};
pub use kind::PatchType;
pub use map::PatchMap;
pub use options::{EndCaps, MAX_ISOLATION, PatchOptions};
pub use param::{PatchParam, PatchPlace};
pub use patch_eval::PatchWeights;
pub use table::{
    PatchArrayLayout, PatchCensus, PatchGrid, PatchTable, PatchTableLayout, TablePoints,
};
