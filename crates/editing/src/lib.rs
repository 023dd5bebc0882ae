//! Constraint-based editing of subdivision limit surfaces (Li, Zhou and Zhang 2008,
//! "Interactive shape modification of Catmull-Clark surfaces") and simple constrained
//! deformation (Sun et al. 2012 §3).
//!
//! Grab the *limit surface*: "this point goes there, the normal here points that way, this
//! iso-line follows this curve". Each [`Constraint`] becomes sparse linear rows over the
//! control vertices, read from subd-limit's exact stencils ([`LimitEvaluator::stencil`]), so
//! anything the evaluator covers can be constrained: boundaries, creases, points at and
//! near extraordinary vertices. The changes of the control vertices are then chosen
//! ([`Method`]):
//!
//! * **least squares**: the smallest change (`ΔX = A⁺ r`), touching only the vertices that
//!   influence the constraints;
//! * **energy**: the fairest change, minimising the thin-plate (+ membrane) energy of the
//!   displacement ([`energy`]) over a region of influence, exactly (KKT) or with Li et al.'s
//!   penalty.
//!
//! An [`Editor`] factors once per set of constraint locations; [`Editor::solve`] with new
//! targets only substitutes. Constraints whose rows are dependent are named in
//! [`Edit::dependencies`]: redundant when their targets agree, conflicting when not.
//! [`edit_mesh`] runs one edit of a mesh start to finish (as `subd edit` does), with the
//! result measured afresh. [`deform`] moves points by radial blends around constraint points (Borrel & Moreau's
//! Scodef), for a mesh of any level.
//!
//! ```
//! use subd_editing::{Constraint, Editor, Goal, Location, Method};
//! use subd_limit::eval::FaceParam;
//! use subd_mesh::DVec3;
//! use subd_schemes::{Options, Scheme};
//!
//! let mesh = subd_mesh::primitives::torus(32, 16, 2.0, 0.5);
//! let at = Location::Face(FaceParam { face: 5, sub: 0, u: 0.25, v: 0.5 });
//! let constraints = vec![
//!     Constraint::Point { at, goal: Goal::Displacement(DVec3::new(0.0, 0.0, 0.2)) },
//!     Constraint::Normal { at, normal: DVec3::new(0.3, 0.0, 1.0) },
//! ];
//! let method = Method::Energy {
//!     penalty: None,
//!     region_rings: Some(2),
//!     energy: Default::default(),
//! };
//! let editor = Editor::new(&mesh.topology, &mesh.positions, &Scheme::CatmullClark,
//!                          &Options::default(), &constraints, method).unwrap();
//! let edit = editor.solve(&constraints).unwrap();
//! // Only vertices near face 5 moved.
//! assert!(edit.moved.len() < mesh.positions.len() / 2);
//! ```
//!
//! [`LimitEvaluator::stencil`]: subd_limit::eval::LimitEvaluator::stencil

pub mod check;
pub mod constraint;
pub mod deform;
pub mod dependency;
pub mod energy;
pub mod isoline;
pub mod mesh_edit;
pub mod report;
pub mod solve;
pub mod spec;

pub use constraint::{Constraint, ConstraintRows, Coupling, Goal, Location, Row};
pub use deform::{DeformConstraint, Deformation};
pub use dependency::DependentGroup;
pub use energy::{EnergyMatrix, EnergyOptions};
pub use isoline::{Axis, Isoline};
pub use mesh_edit::{Energies, Measured, MeshEdit, edit_mesh};
pub use report::{ConstraintResidual, EditReport, EditSeconds};
pub use solve::{Edit, Editor, Method, MethodKind, MethodRequest, Timings};

#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

use thiserror::Error;

/// What can go wrong.
#[derive(Debug, Error)]
pub enum EditError {
    /// A constraint that cannot be built (named by its index in the list).
    #[error("constraint {index}: {message}")]
    Constraint {
        /// Index in the list.
        index: usize,
        /// Why.
        message: String,
    },
    /// A deformation constraint that cannot be used.
    #[error("deformation constraint {index}: {message}")]
    Deform {
        /// Index in the list.
        index: usize,
        /// Why.
        message: String,
    },
    /// The limit evaluator rejected the mesh.
    #[error(transparent)]
    Limit(#[from] subd_limit::LimitError),
    /// The energy method on a scheme without its thin-plate form here.
    #[error("the energy method needs catmull-clark (use least-squares for loop)")]
    EnergyScheme,
    /// A factorisation or solve failed.
    #[error("{0}")]
    Solve(String),
}
