//! [`Scheme`]: the one name of every surface scheme, and the facts about it that callers
//! would otherwise re-derive (input faces, split, interpolation, which tags it honours).

use std::fmt;
use std::str::FromStr;

use thiserror::Error;

use subd_mesh::Topology;

use crate::TwoPhase;
use crate::split_schemes::SplitStep;

/// A surface subdivision scheme: OpenSubdiv's three, seed 000's two-phase scheme, and the
/// four split schemes of seed 001 §4.
///
/// Every refinement, limit, evaluation, interpolation and editing entry of subd takes this
/// type. [`FromStr`] and [`Display`](fmt::Display) use the command line's names; a parameter
/// follows a colon (`butterfly:0.05`, `two-phase:0.6`) and has a default where the scheme
/// has one (the butterfly's tension is 1/16).
///
/// ```
/// use subd_schemes::{FaceKind, Scheme};
///
/// let s: Scheme = "sqrt3".parse().unwrap();
/// assert_eq!(s, Scheme::Sqrt3);
/// assert_eq!(s.input_faces(), FaceKind::Triangles);
/// assert_eq!(s.period(), 2); // √3 turns the mesh in two steps
/// assert_eq!("butterfly".parse::<Scheme>().unwrap(), Scheme::BUTTERFLY);
/// assert_eq!(Scheme::Butterfly { tension: 0.05 }.to_string(), "butterfly:0.05");
/// assert!("catmull-clark".parse::<Scheme>().unwrap().tags().semi_sharp_creases);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum Scheme {
    /// Catmull-Clark: any polygons, quads after one level.
    CatmullClark,
    /// Loop: triangles only.
    Loop,
    /// Bilinear: the quad split with linear interpolation.
    Bilinear,
    /// Seed 000's two-phase modified Catmull-Clark: level 1 is phase 1 with shape parameter
    /// `λ` (one for all vertices or one per vertex), Catmull-Clark after it (see
    /// [`two_phase`](crate::two_phase)).
    TwoPhase(TwoPhase),
    /// Doo-Sabin's dual scheme on any polygons.
    DooSabin,
    /// Kobbelt's √3 scheme on triangles.
    Sqrt3,
    /// The butterfly scheme of Dyn, Levin and Gregory with tension `w` (1/16 is the classic
    /// one; 0 is linear interpolation).
    Butterfly {
        /// The tension `w`.
        tension: f64,
    },
    /// The modified butterfly scheme of Zorin, Schröder and Sweldens.
    ModifiedButterfly,
}

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

/// Why a scheme name does not parse.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum ParseSchemeError {
    /// No scheme has this name.
    #[error(
        "unknown scheme `{0}` (expected catmull-clark, loop, bilinear, two-phase, doo-sabin, sqrt3, butterfly or modified-butterfly)"
    )]
    Unknown(String),
    /// A parameter that is not a number, or that the scheme does not take.
    #[error("scheme `{scheme}`: {why}")]
    Parameter {
        /// The scheme's name.
        scheme: String,
        /// What is wrong.
        why: String,
    },
}

impl Scheme {
    /// The classic butterfly, `w = 1/16`.
    pub const BUTTERFLY: Scheme = Scheme::Butterfly {
        tension: 1.0 / 16.0,
    };

    /// Every scheme name, in the order the documentation lists them.
    pub const NAMES: [&'static str; 8] = [
        "catmull-clark",
        "loop",
        "bilinear",
        "two-phase",
        "doo-sabin",
        "sqrt3",
        "butterfly",
        "modified-butterfly",
    ];

    /// The scheme's name as the command line spells it (without parameters).
    pub fn name(&self) -> &'static str {
        match self {
            Scheme::CatmullClark => "catmull-clark",
            Scheme::Loop => "loop",
            Scheme::Bilinear => "bilinear",
            Scheme::TwoPhase(_) => "two-phase",
            Scheme::DooSabin => "doo-sabin",
            Scheme::Sqrt3 => "sqrt3",
            Scheme::Butterfly { .. } => "butterfly",
            Scheme::ModifiedButterfly => "modified-butterfly",
        }
    }

    /// Whether the scheme is one of OpenSubdiv's (or the two-phase scheme, which refines
    /// with Catmull-Clark's topology and rules): the family that reproduces OpenSubdiv's
    /// vertex order, crease semantics and options.
    pub fn is_opensubdiv(&self) -> bool {
        matches!(
            self,
            Scheme::CatmullClark | Scheme::Loop | Scheme::Bilinear | Scheme::TwoPhase(_)
        )
    }

    /// The scheme a mesh file names (USD's `subdivisionScheme`); `None` for a file that
    /// says its mesh is plain polygons (`none`).
    ///
    /// ```
    /// use subd_mesh::FileScheme;
    /// use subd_schemes::Scheme;
    /// assert_eq!(Scheme::from_file(FileScheme::Loop), Some(Scheme::Loop));
    /// assert_eq!(Scheme::from_file(FileScheme::Polygons), None);
    /// assert_eq!(Scheme::DooSabin.file_scheme(), None);
    /// ```
    pub fn from_file(named: subd_mesh::FileScheme) -> Option<Scheme> {
        match named {
            subd_mesh::FileScheme::CatmullClark => Some(Scheme::CatmullClark),
            subd_mesh::FileScheme::Loop => Some(Scheme::Loop),
            subd_mesh::FileScheme::Bilinear => Some(Scheme::Bilinear),
            subd_mesh::FileScheme::Polygons => None,
        }
    }

    /// How a mesh file names this scheme, where it can: USD names Catmull-Clark, Loop and
    /// Bilinear; the other schemes (and the two-phase scheme, whose λ no file carries) have
    /// no name there.
    pub fn file_scheme(&self) -> Option<subd_mesh::FileScheme> {
        match self {
            Scheme::CatmullClark => Some(subd_mesh::FileScheme::CatmullClark),
            Scheme::Loop => Some(subd_mesh::FileScheme::Loop),
            Scheme::Bilinear => Some(subd_mesh::FileScheme::Bilinear),
            _ => None,
        }
    }

    /// The faces the scheme takes.
    pub fn input_faces(&self) -> FaceKind {
        match self {
            Scheme::CatmullClark | Scheme::Bilinear | Scheme::DooSabin => FaceKind::Any,
            Scheme::TwoPhase(_) => FaceKind::Quads,
            Scheme::Loop | Scheme::Sqrt3 | Scheme::Butterfly { .. } | Scheme::ModifiedButterfly => {
                FaceKind::Triangles
            }
        }
    }

    /// How one step splits the faces.
    pub fn split(&self) -> Split {
        match self {
            Scheme::CatmullClark | Scheme::Bilinear | Scheme::TwoPhase(_) => Split::Quad,
            Scheme::Loop | Scheme::Butterfly { .. } | Scheme::ModifiedButterfly => Split::Triangle,
            Scheme::Sqrt3 => Split::Sqrt3,
            Scheme::DooSabin => Split::Dual,
        }
    }

    /// Child faces per parent face of the kind the scheme produces (4 for the quad and
    /// triangle splits, 3 for √3); `None` for Doo-Sabin, whose dual split makes faces of
    /// edges and vertices too.
    pub fn split_arity(&self) -> Option<usize> {
        match self.split() {
            Split::Quad | Split::Triangle => Some(4),
            Split::Sqrt3 => Some(3),
            Split::Dual => None,
        }
    }

    /// Steps after which the split repeats itself: 2 for √3 (each step turns the mesh, and
    /// the boundary is trisected every second step), 1 for the others.
    pub fn period(&self) -> usize {
        if *self == Scheme::Sqrt3 { 2 } else { 1 }
    }

    /// Whether the vertices of every level stay on the limit surface (Bilinear and the
    /// butterflies).
    pub fn is_interpolating(&self) -> bool {
        matches!(
            self,
            Scheme::Bilinear | Scheme::Butterfly { .. } | Scheme::ModifiedButterfly
        )
    }

    /// Regular interior valence: 6 for the triangle schemes, 4 for the others.
    pub fn regular_valence(&self) -> usize {
        if self.input_faces() == FaceKind::Triangles {
            6
        } else {
            4
        }
    }

    /// The tags the scheme has rules for.
    pub fn tags(&self) -> TagSupport {
        let opensubdiv = TagSupport {
            semi_sharp_creases: true,
            infinite_creases: true,
            corners: true,
            holes: true,
            non_manifold: true,
            fvar_modes: true,
            uv_seams: true,
        };
        let split = TagSupport {
            semi_sharp_creases: false,
            infinite_creases: true,
            corners: true,
            holes: false,
            non_manifold: false,
            fvar_modes: false,
            uv_seams: false,
        };
        match self {
            Scheme::CatmullClark | Scheme::Loop | Scheme::TwoPhase(_) => opensubdiv,
            // Bilinear keeps every vertex and edge: sharpness changes nothing.
            Scheme::Bilinear => TagSupport {
                semi_sharp_creases: false,
                infinite_creases: false,
                corners: false,
                ..opensubdiv
            },
            Scheme::DooSabin => TagSupport {
                infinite_creases: false,
                corners: false,
                ..split
            },
            Scheme::Sqrt3 => split,
            Scheme::Butterfly { .. } | Scheme::ModifiedButterfly => TagSupport {
                uv_seams: true,
                ..split
            },
        }
    }

    /// One line on the scheme: who it is by, the faces it takes, and its parameter.
    pub fn summary(&self) -> &'static str {
        match self {
            Scheme::CatmullClark => "Catmull-Clark (OpenSubdiv's), any polygons",
            Scheme::Loop => "Loop (OpenSubdiv's), triangles",
            Scheme::Bilinear => "Bilinear (OpenSubdiv's), any polygons",
            Scheme::TwoPhase(_) => {
                "Seed 000's two-phase modified Catmull-Clark, quads; shape parameter λ (two-phase:λ)"
            }
            Scheme::DooSabin => "Doo-Sabin's dual scheme, any polygons",
            Scheme::Sqrt3 => "Kobbelt's √3 scheme, triangles",
            Scheme::Butterfly { .. } => {
                "The interpolating butterfly (Dyn, Levin, Gregory), triangles; tension w (butterfly:w, default 1/16)"
            }
            Scheme::ModifiedButterfly => {
                "Zorin, Schröder and Sweldens' modified butterfly, triangles"
            }
        }
    }

    /// Bytes per output vertex at the peak of refining and writing with this scheme, held
    /// and (OpenSubdiv's schemes) streamed from the level above: measured with
    /// `/usr/bin/time -f %M` on the bench torus and its triangulation, levels 1–4, rounded
    /// up (BENCHMARKS.md, "Memory estimates"; see [`crate::peak::PeakModel`]). The two-phase
    /// scheme is Catmull-Clark's after level 1; the split schemes hold every level.
    pub fn peak_bytes_per_vertex(&self) -> (u64, Option<u64>) {
        match self {
            Scheme::CatmullClark | Scheme::TwoPhase(_) => (105, Some(70)),
            Scheme::Bilinear => (120, Some(70)),
            Scheme::Loop => (120, Some(90)),
            Scheme::DooSabin => (145, None),
            Scheme::Butterfly { .. } | Scheme::ModifiedButterfly => (190, None),
            Scheme::Sqrt3 => (235, None),
        }
    }

    /// The scheme's parameter checked: the butterfly's tension must be finite (the
    /// two-phase scheme's `λ` is checked where it is set, [`TwoPhase`]).
    pub(crate) fn check_parameters(&self) -> Result<(), crate::RefineError> {
        match *self {
            Scheme::Butterfly { tension } if !tension.is_finite() => {
                Err(crate::RefineError::Tension(tension))
            }
            _ => Ok(()),
        }
    }

    /// The split scheme that carries face-varying values on this scheme's topology when
    /// they interpolate linearly everywhere (`FVarLinearInterpolation::All`): the butterfly
    /// with tension 0 (edge midpoints, old values kept) for the butterflies; Doo-Sabin and √3
    /// carry values with their own masks, their values being a mesh of their own.
    pub(crate) fn linear_values(&self) -> Scheme {
        match self {
            Scheme::Butterfly { .. } | Scheme::ModifiedButterfly => {
                Scheme::Butterfly { tension: 0.0 }
            }
            s => s.clone(),
        }
    }

    /// One step of a split scheme over `parent`, the child being level `level`: the scheme's
    /// rule file ([`crate::split_schemes`]). `None` for OpenSubdiv's schemes and the
    /// two-phase scheme, whose family has its own tables.
    pub(crate) fn split_step<'a>(
        &self,
        parent: &'a Topology,
        level: usize,
    ) -> Option<Box<dyn SplitStep + 'a>> {
        use crate::split_schemes::{butterfly, doo_sabin, sqrt3};
        Some(match self {
            Scheme::DooSabin => Box::new(doo_sabin::Step::new(parent)),
            // √3 trisects boundary edges every second step.
            Scheme::Sqrt3 => Box::new(sqrt3::Step::new(parent, level % 2 == 0)),
            Scheme::Butterfly { tension } => Box::new(butterfly::Step::new(
                parent,
                butterfly::EdgeRule::Classic { tension: *tension },
            )),
            Scheme::ModifiedButterfly => {
                Box::new(butterfly::Step::new(parent, butterfly::EdgeRule::Modified))
            }
            Scheme::CatmullClark | Scheme::Loop | Scheme::Bilinear | Scheme::TwoPhase(_) => {
                return None;
            }
        })
    }

    /// The scheme whose rules a mesh at `level` of a refinement with this scheme follows
    /// from then on: Catmull-Clark for the two-phase scheme's refined levels (phase 1 is its
    /// first step only), the scheme itself otherwise.
    ///
    /// ```
    /// use subd_schemes::Scheme;
    ///
    /// let tp: Scheme = "two-phase:0.6".parse().unwrap();
    /// assert_eq!(tp.at_level(0), tp);
    /// assert_eq!(tp.at_level(2), Scheme::CatmullClark);
    /// assert_eq!(Scheme::Sqrt3.at_level(3), Scheme::Sqrt3);
    /// ```
    pub fn at_level(&self, level: usize) -> Scheme {
        match self {
            Scheme::TwoPhase(_) if level > 0 => Scheme::CatmullClark,
            s => s.clone(),
        }
    }

    /// The butterfly's tension, when this is the butterfly scheme.
    pub fn tension(&self) -> Option<f64> {
        match self {
            Scheme::Butterfly { tension } => Some(*tension),
            _ => None,
        }
    }

    /// The two-phase scheme's shape parameters, when this is the two-phase scheme.
    pub fn two_phase(&self) -> Option<&TwoPhase> {
        match self {
            Scheme::TwoPhase(tp) => Some(tp),
            _ => None,
        }
    }
}

impl fmt::Display for Scheme {
    /// The name, with the parameter where it is not the default and is one number.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())?;
        match self {
            Scheme::Butterfly { tension } if *self != Scheme::BUTTERFLY => {
                write!(f, ":{tension}")
            }
            Scheme::TwoPhase(tp) => match tp.uniform_lambda() {
                Some(l) => write!(f, ":{l}"),
                None => Ok(()),
            },
            _ => Ok(()),
        }
    }
}

impl FromStr for Scheme {
    type Err = ParseSchemeError;

    /// A scheme name, optionally followed by `:` and the scheme's one parameter: the
    /// butterfly's tension (default 1/16), the two-phase scheme's `λ` for every vertex
    /// (checked to lie in (7/20, 1]; without it the `λ` must be given before refining,
    /// [`TwoPhase::unset`]).
    fn from_str(s: &str) -> Result<Scheme, ParseSchemeError> {
        let (name, parameter) = match s.split_once(':') {
            Some((n, p)) => (n, Some(p)),
            None => (s, None),
        };
        let number = |p: &str| {
            p.trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| ParseSchemeError::Parameter {
                    scheme: name.to_string(),
                    why: format!("`{p}` is not a finite number"),
                })
        };
        let scheme = match name {
            "catmull-clark" => Scheme::CatmullClark,
            "loop" => Scheme::Loop,
            "bilinear" => Scheme::Bilinear,
            "doo-sabin" => Scheme::DooSabin,
            "sqrt3" => Scheme::Sqrt3,
            "modified-butterfly" => Scheme::ModifiedButterfly,
            "butterfly" => {
                return Ok(match parameter {
                    Some(p) => Scheme::Butterfly {
                        tension: number(p)?,
                    },
                    None => Scheme::BUTTERFLY,
                });
            }
            "two-phase" => {
                return Ok(Scheme::TwoPhase(match parameter {
                    Some(p) => {
                        TwoPhase::uniform(number(p)?).map_err(|e| ParseSchemeError::Parameter {
                            scheme: name.to_string(),
                            why: e.to_string(),
                        })?
                    }
                    None => TwoPhase::unset(),
                }));
            }
            _ => return Err(ParseSchemeError::Unknown(s.to_string())),
        };
        match parameter {
            Some(p) => Err(ParseSchemeError::Parameter {
                scheme: name.to_string(),
                why: format!("takes no parameter (`{p}` given)"),
            }),
            None => Ok(scheme),
        }
    }
}

impl serde::Serialize for Scheme {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Scheme {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Scheme, D::Error> {
        let s = <std::borrow::Cow<'de, str>>::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for name in Scheme::NAMES {
            let s: Scheme = name.parse().unwrap();
            assert_eq!(s.name(), name);
            assert_eq!(s.to_string(), name);
        }
        let b: Scheme = "butterfly:0.05".parse().unwrap();
        assert_eq!(b, Scheme::Butterfly { tension: 0.05 });
        assert_eq!(b.to_string().parse::<Scheme>().unwrap(), b);
        let tp: Scheme = "two-phase:0.6".parse().unwrap();
        assert_eq!(tp.to_string(), "two-phase:0.6");
        assert_eq!(tp.two_phase().unwrap().uniform_lambda(), Some(0.6));
    }

    #[test]
    fn bad_names_and_parameters() {
        assert!(matches!(
            "catmul-clark".parse::<Scheme>(),
            Err(ParseSchemeError::Unknown(_))
        ));
        for bad in ["loop:1", "butterfly:x", "butterfly:inf", "two-phase:0.2"] {
            assert!(
                matches!(
                    bad.parse::<Scheme>(),
                    Err(ParseSchemeError::Parameter { .. })
                ),
                "{bad}"
            );
        }
    }

    #[test]
    fn facts() {
        let all: Vec<Scheme> = Scheme::NAMES.iter().map(|n| n.parse().unwrap()).collect();
        let triangles: Vec<&str> = all
            .iter()
            .filter(|s| s.input_faces() == FaceKind::Triangles)
            .map(|s| s.name())
            .collect();
        assert_eq!(
            triangles,
            ["loop", "sqrt3", "butterfly", "modified-butterfly"]
        );
        assert_eq!(Scheme::DooSabin.split_arity(), None);
        assert_eq!(Scheme::Sqrt3.split_arity(), Some(3));
        assert_eq!(Scheme::Loop.regular_valence(), 6);
        assert_eq!(Scheme::DooSabin.regular_valence(), 4);
        assert!(!Scheme::DooSabin.tags().corners && Scheme::Sqrt3.tags().corners);
        assert!(Scheme::ModifiedButterfly.tags().uv_seams && !Scheme::Sqrt3.tags().uv_seams);
        assert_eq!(
            all.iter().filter(|s| s.is_opensubdiv()).count(),
            4,
            "Catmull-Clark, Loop, Bilinear and two-phase"
        );
    }

    #[test]
    fn serde_uses_the_names() {
        let s = Scheme::Butterfly { tension: 0.1 };
        let text = serde_json::to_string(&s).unwrap();
        assert_eq!(text, "\"butterfly:0.1\"");
        assert_eq!(serde_json::from_str::<Scheme>(&text).unwrap(), s);
    }
}
