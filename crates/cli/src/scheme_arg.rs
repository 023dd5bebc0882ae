//! The one `--scheme` parser: every command reads a [`Scheme`] with it, from the names (and
//! `:parameter`s) that `Scheme`'s `FromStr` takes, limited to the schemes that command
//! covers. The butterfly's `--tension` and the two-phase scheme's `--lambda` and
//! `--lambda-file` complete the parsed scheme ([`with_tension`], [`with_lambda`]).

use std::ffi::OsStr;
use std::path::Path;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::error::ErrorKind;
use subd_schemes::Scheme;

use crate::Failure;
use crate::failure::bad;
use crate::vertex_data::LambdaArgs;

/// Every surface scheme (`refine`, `render`).
pub(crate) const ALL: &[&str] = &Scheme::NAMES;
/// Schemes with a limit surface other than the mesh itself (`limit`).
pub(crate) const WITH_LIMIT: &[&str] = &[
    "catmull-clark",
    "loop",
    "two-phase",
    "doo-sabin",
    "sqrt3",
    "butterfly",
    "modified-butterfly",
];
/// Schemes whose limit is evaluated exactly at any (face, u, v) (`eval`, `tessellate`,
/// `edit`, `deform`, `adaptive`).
pub(crate) const EVALUATED: &[&str] = &["catmull-clark", "loop"];
/// Schemes whose limit surface interpolates (`pia`).
pub(crate) const INTERPOLATED: &[&str] = &["catmull-clark", "loop", "two-phase"];
/// Schemes with a local subdivision matrix at a valence (`analyze --surface`).
pub(crate) const ANALYSED: &[&str] = &[
    "catmull-clark",
    "loop",
    "doo-sabin",
    "sqrt3",
    "butterfly",
    "modified-butterfly",
];

/// A clap value parser giving a [`Scheme`], accepting the names in `accepted`.
pub(crate) fn parser(accepted: &'static [&'static str]) -> SchemeParser {
    SchemeParser { accepted }
}

/// See [`parser`].
#[derive(Clone)]
pub(crate) struct SchemeParser {
    accepted: &'static [&'static str],
}

impl TypedValueParser for SchemeParser {
    type Value = Scheme;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<Scheme, clap::Error> {
        let text = value.to_string_lossy();
        let name = text.split(':').next().unwrap_or_default();
        // An unknown name gets clap's own message, which lists the accepted ones.
        PossibleValuesParser::new(self.possible_values_list()).parse_ref(
            cmd,
            arg,
            OsStr::new(name),
        )?;
        text.parse::<Scheme>().map_err(|e| {
            let flag = arg.map_or_else(|| "--scheme".to_string(), ToString::to_string);
            clap::Error::raw(
                ErrorKind::InvalidValue,
                format!("invalid value '{text}' for '{flag}': {e}\n"),
            )
            .with_cmd(cmd)
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(self.possible_values_list().into_iter()))
    }
}

impl SchemeParser {
    fn possible_values_list(&self) -> Vec<PossibleValue> {
        self.accepted
            .iter()
            .map(|&name| PossibleValue::new(name).help(help(name)))
            .collect()
    }
}

/// One line on each scheme for `--help`.
fn help(name: &str) -> &'static str {
    match name {
        "catmull-clark" => "Catmull-Clark (OpenSubdiv's), any polygons",
        "loop" => "Loop (OpenSubdiv's), triangles",
        "bilinear" => "Bilinear (OpenSubdiv's), any polygons",
        "two-phase" => {
            "Seed 000's two-phase modified Catmull-Clark, quads (needs --lambda or --lambda-file, or two-phase:λ)"
        }
        "doo-sabin" => "Doo-Sabin's dual scheme, any polygons",
        "sqrt3" => "Kobbelt's √3 scheme, triangles",
        "butterfly" => {
            "The interpolating butterfly (Dyn, Levin, Gregory), triangles; tension w by --tension or butterfly:w (default 1/16)"
        }
        "modified-butterfly" => "Zorin, Schröder and Sweldens' modified butterfly, triangles",
        _ => "",
    }
}

/// `scheme` with the butterfly's `--tension`; the flag applies to the butterfly only (named
/// `flag` in the message).
pub(crate) fn with_tension(
    scheme: &Scheme,
    tension: Option<f64>,
    flag: &str,
) -> Result<Scheme, Failure> {
    match (scheme, tension) {
        (_, None) => Ok(scheme.clone()),
        (Scheme::Butterfly { .. }, Some(_)) => Ok(Scheme::Butterfly {
            tension: crate::rule_args::butterfly_tension(tension)?,
        }),
        (_, Some(_)) => Err(bad(format!("--tension applies to {flag} butterfly only"))),
    }
}

/// `scheme` with the two-phase scheme's `λ` from `--lambda` or `--lambda-file` for a mesh
/// of `num_vertices` vertices read from `input`: the flags apply to the two-phase scheme
/// only, which needs them unless its `λ` came with its name (`two-phase:0.6`).
pub(crate) fn with_lambda(
    scheme: &Scheme,
    lambda: &LambdaArgs,
    input: &Path,
    num_vertices: usize,
) -> Result<Scheme, Failure> {
    match scheme {
        Scheme::TwoPhase(tp) if tp.is_set() => match lambda.given() {
            true => Err(bad(
                "--lambda and --lambda-file: two-phase:λ gives the λ already".into(),
            )),
            false => Ok(scheme.clone()),
        },
        Scheme::TwoPhase(_) => Ok(Scheme::TwoPhase(lambda.two_phase(input, num_vertices)?)),
        _ if lambda.given() => Err(bad(
            "--lambda and --lambda-file apply to --scheme two-phase only".into(),
        )),
        _ => Ok(scheme.clone()),
    }
}

/// Whether `scheme` is the two-phase scheme, with or without its `λ`.
pub(crate) fn is_two_phase(scheme: &Scheme) -> bool {
    matches!(scheme, Scheme::TwoPhase(_))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(accepted: &'static [&'static str], text: &str) -> Result<Scheme, String> {
        let cmd = clap::Command::new("t");
        parser(accepted)
            .parse_ref(&cmd, None, OsStr::new(text))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn names_and_parameters_parse_to_the_library_scheme() {
        assert_eq!(parse(ALL, "sqrt3").unwrap(), Scheme::Sqrt3);
        assert_eq!(
            parse(ALL, "butterfly:0.05").unwrap(),
            Scheme::Butterfly { tension: 0.05 }
        );
        let two_phase = parse(INTERPOLATED, "two-phase:0.6").unwrap();
        assert_eq!(two_phase.two_phase().unwrap().uniform_lambda(), Some(0.6));
        assert!(
            !parse(INTERPOLATED, "two-phase")
                .unwrap()
                .two_phase()
                .unwrap()
                .is_set()
        );
    }

    #[test]
    fn names_outside_the_command_and_bad_parameters_are_refused() {
        let e = parse(EVALUATED, "sqrt3").unwrap_err();
        assert!(
            e.contains("'sqrt3'") && e.contains("catmull-clark, loop"),
            "{e}"
        );
        let e = parse(ALL, "butterfly:x").unwrap_err();
        assert!(
            e.contains("butterfly:x") && e.contains("not a finite number"),
            "{e}"
        );
        let e = parse(ALL, "loop:2").unwrap_err();
        assert!(e.contains("takes no parameter"), "{e}");
        // Every accepted list names schemes the library knows.
        for list in [ALL, WITH_LIMIT, EVALUATED, INTERPOLATED, ANALYSED] {
            for name in list {
                assert!(name.parse::<Scheme>().is_ok(), "{name}");
                assert!(!help(name).is_empty(), "{name}");
            }
        }
    }

    #[test]
    fn tension_and_lambda_apply_to_their_scheme_only() {
        let b = with_tension(&Scheme::BUTTERFLY, Some(0.1), "--scheme").unwrap();
        assert_eq!(b, Scheme::Butterfly { tension: 0.1 });
        let e = with_tension(&Scheme::Loop, Some(0.1), "--scheme").unwrap_err();
        assert_eq!(e.message, "--tension applies to --scheme butterfly only");
        assert_eq!(
            with_tension(&Scheme::Loop, None, "--scheme").unwrap(),
            Scheme::Loop
        );
    }
}
