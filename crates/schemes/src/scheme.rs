//! [`Scheme`]: the one name of every surface scheme, and the facts about it that callers
//! would otherwise re-derive (input faces, split, interpolation, which tags it honours).

use std::fmt;
use std::str::FromStr;

use thiserror::Error;

use subd_mesh::Topology;

use crate::TwoPhase;
use crate::facts::{Capability, FaceKind, SchemeFacts, Split, TagSupport};
use crate::split_schemes::SplitStep;

/// A surface subdivision scheme: OpenSubdiv's three, Lin et al.'s two-phase scheme, and the
/// four split schemes of the subdivision lecture notes §4.
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
    /// Lin et al.'s two-phase modified Catmull-Clark: level 1 is phase 1 with shape parameter
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

/// Why a scheme name does not parse.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum ParseSchemeError {
    /// No scheme has this name.
    #[error("unknown scheme `{0}` (expected {names})", names = sentence(&Scheme::NAMES))]
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

/// Every scheme's facts, in [`Scheme::NAMES`] order, each from its rule file.
const ALL_FACTS: [&SchemeFacts; 8] = [
    &crate::refine::CATMULL_CLARK,
    &crate::refine::LOOP,
    &crate::refine::BILINEAR,
    &crate::two_phase::FACTS,
    &crate::split_schemes::doo_sabin::FACTS,
    &crate::split_schemes::sqrt3::FACTS,
    &crate::split_schemes::butterfly::FACTS,
    &crate::split_schemes::butterfly::MODIFIED_FACTS,
];

/// Names as a sentence lists them: `a`, `a or b`, `a, b or c`.
fn sentence(names: &[&str]) -> String {
    match names.split_last() {
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

impl Scheme {
    /// The classic butterfly, `w = 1/16`.
    pub const BUTTERFLY: Scheme = Scheme::Butterfly {
        tension: 1.0 / 16.0,
    };

    /// Every scheme name, in the order the documentation lists them.
    pub const NAMES: [&'static str; 8] = [
        ALL_FACTS[0].name,
        ALL_FACTS[1].name,
        ALL_FACTS[2].name,
        ALL_FACTS[3].name,
        ALL_FACTS[4].name,
        ALL_FACTS[5].name,
        ALL_FACTS[6].name,
        ALL_FACTS[7].name,
    ];

    /// The scheme's facts, as its rule file declares them.
    ///
    /// ```
    /// use subd_schemes::{Capability, Scheme, Split};
    ///
    /// let facts = Scheme::Sqrt3.facts();
    /// assert_eq!((facts.name, facts.split), ("sqrt3", Split::Sqrt3));
    /// assert!(facts.capabilities.contains(&Capability::Limit));
    /// ```
    pub fn facts(&self) -> &'static SchemeFacts {
        match self {
            Scheme::CatmullClark => ALL_FACTS[0],
            Scheme::Loop => ALL_FACTS[1],
            Scheme::Bilinear => ALL_FACTS[2],
            Scheme::TwoPhase(_) => ALL_FACTS[3],
            Scheme::DooSabin => ALL_FACTS[4],
            Scheme::Sqrt3 => ALL_FACTS[5],
            Scheme::Butterfly { .. } => ALL_FACTS[6],
            Scheme::ModifiedButterfly => ALL_FACTS[7],
        }
    }

    /// Whether subd computes `capability` for this scheme.
    ///
    /// ```
    /// use subd_schemes::{Capability, Scheme};
    ///
    /// assert!(Scheme::Loop.supports(Capability::Evaluate));
    /// assert!(!Scheme::Sqrt3.supports(Capability::Evaluate));
    /// assert!(!Scheme::Bilinear.supports(Capability::Limit));
    /// ```
    pub fn supports(&self, capability: Capability) -> bool {
        self.facts().capabilities.contains(&capability)
    }

    /// The names of the schemes with `capability`, in [`Self::NAMES`] order.
    ///
    /// ```
    /// use subd_schemes::{Capability, Scheme};
    ///
    /// assert_eq!(Scheme::names_with(Capability::Edit), ["catmull-clark", "loop"]);
    /// ```
    pub fn names_with(capability: Capability) -> Vec<&'static str> {
        ALL_FACTS
            .iter()
            .filter(|f| f.capabilities.contains(&capability))
            .map(|f| f.name)
            .collect()
    }

    /// [`Self::names_with`] as a sentence lists them, for messages: "catmull-clark or
    /// loop", "catmull-clark, loop or two-phase".
    pub fn list_with(capability: Capability) -> String {
        sentence(&Self::names_with(capability))
    }

    /// The scheme's name as the command line spells it (without parameters).
    pub fn name(&self) -> &'static str {
        self.facts().name
    }

    /// Whether the scheme is one of OpenSubdiv's (or the two-phase scheme, which refines
    /// with Catmull-Clark's topology and rules): the family that reproduces OpenSubdiv's
    /// vertex order, crease semantics and options.
    pub fn is_opensubdiv(&self) -> bool {
        self.facts().opensubdiv_family
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
        self.facts().input_faces
    }

    /// How one step splits the faces.
    pub fn split(&self) -> Split {
        self.facts().split
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
        if self.split() == Split::Sqrt3 { 2 } else { 1 }
    }

    /// Whether the vertices of every level stay on the limit surface (Bilinear and the
    /// butterflies).
    pub fn is_interpolating(&self) -> bool {
        self.facts().interpolating
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
        self.facts().tags
    }

    /// One line on the scheme: who it is by, the faces it takes, and its parameter.
    pub fn summary(&self) -> &'static str {
        self.facts().summary
    }

    /// Bytes per output vertex at the peak of refining and writing with this scheme, held
    /// and (OpenSubdiv's schemes) streamed from the level above: measured with
    /// `/usr/bin/time -f %M` on the bench torus and its triangulation, levels 1–4, rounded
    /// up (BENCHMARKS.md, "Memory estimates"; see [`crate::peak::PeakModel`]). The two-phase
    /// scheme is Catmull-Clark's after level 1; the split schemes hold every level.
    pub fn peak_bytes_per_vertex(&self) -> (u64, Option<u64>) {
        self.facts().peak_bytes_per_vertex
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
    fn capabilities_are_the_documented_ones() {
        use Capability::*;
        // The README's table of schemes, written out by hand.
        let expected: [(&str, &[Capability]); 8] = [
            (
                "catmull-clark",
                &[
                    Refine,
                    Limit,
                    Evaluate,
                    Interpolate,
                    Edit,
                    Adaptive,
                    Analyse,
                ],
            ),
            (
                "loop",
                &[
                    Refine,
                    Limit,
                    Evaluate,
                    Interpolate,
                    Edit,
                    Adaptive,
                    Analyse,
                ],
            ),
            ("bilinear", &[Refine]),
            ("two-phase", &[Refine, Limit, Interpolate]),
            ("doo-sabin", &[Refine, Limit, Analyse]),
            ("sqrt3", &[Refine, Limit, Analyse]),
            ("butterfly", &[Refine, Limit, Analyse]),
            ("modified-butterfly", &[Refine, Limit, Analyse]),
        ];
        for (name, capabilities) in expected {
            let scheme: Scheme = name.parse().unwrap();
            for c in Capability::ALL {
                assert_eq!(
                    scheme.supports(c),
                    capabilities.contains(&c),
                    "{name} {c:?}"
                );
            }
        }
        assert_eq!(
            Scheme::list_with(Interpolate),
            "catmull-clark, loop or two-phase"
        );
        assert_eq!(Scheme::list_with(Evaluate), "catmull-clark or loop");
        assert_eq!(
            ParseSchemeError::Unknown("x".into()).to_string(),
            "unknown scheme `x` (expected catmull-clark, loop, bilinear, two-phase, doo-sabin, sqrt3, butterfly or modified-butterfly)"
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
