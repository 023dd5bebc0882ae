//! The references subd is compared with, each computed another way: OpenSubdiv through a
//! C++ harness ([`osd`]), CGAL and OpenMesh through another ([`geom`]), and limits from
//! refining deep instead of from masks ([`refined_limits`]).

pub mod geom;
pub mod osd;
pub mod refined_limits;
