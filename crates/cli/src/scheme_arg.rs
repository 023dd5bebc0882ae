//! The one `--scheme` parser: every command reads a [`Scheme`] with it, from the names (and
//! `:parameter`s) that `Scheme`'s `FromStr` takes, limited to the schemes that command
//! covers. The butterfly's `--tension` and the two-phase scheme's `--lambda` and
//! `--lambda-file` complete the parsed scheme ([`with_tension`], [`with_lambda`]).

use std::ffi::OsStr;
use std::path::Path;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::error::ErrorKind;
use subd_mesh::SchemeHints;
use subd_schemes::{Capability, Scheme};

use crate::Failure;
use crate::failure::bad;
use crate::vertex_data::LambdaArgs;

/// A clap value parser giving a [`Scheme`], accepting the schemes with `capability` (the
/// library's list, [`Scheme::names_with`]).
pub(crate) fn parser(capability: Capability) -> SchemeParser {
    SchemeParser {
        accepted: Scheme::names_with(capability)
            .iter()
            .filter_map(|name| name.parse::<Scheme>().ok())
            .collect(),
    }
}

/// See [`parser`].
#[derive(Clone)]
pub(crate) struct SchemeParser {
    accepted: Vec<Scheme>,
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
            .map(|s| PossibleValue::new(s.name()).help(s.summary()))
            .collect()
    }
}

/// The scheme a command runs on `input`: `--scheme` when given, else the one the file
/// names (USD's `subdivisionScheme`) if it has the `capability` the command needs.
pub(crate) fn given_or_named(
    given: Option<&Scheme>,
    hints: &SchemeHints,
    capability: Capability,
    input: &Path,
) -> Result<Scheme, Failure> {
    if let Some(s) = given {
        return Ok(s.clone());
    }
    let named = hints.scheme.ok_or_else(|| {
        bad(format!(
            "{}: no --scheme given, and the file names no subdivision scheme",
            input.display()
        ))
    })?;
    let scheme = Scheme::from_file(named).ok_or_else(|| {
        bad(format!(
            "{}: the file names no subdivision scheme (subdivisionScheme none): give --scheme",
            input.display()
        ))
    })?;
    if scheme.supports(capability) {
        Ok(scheme)
    } else {
        Err(bad(format!(
            "{}: the file's scheme {scheme} is not one this command takes ({capability} needs {}): give --scheme",
            input.display(),
            Scheme::list_with(capability)
        )))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(accepted: Capability, text: &str) -> Result<Scheme, String> {
        let cmd = clap::Command::new("t");
        parser(accepted)
            .parse_ref(&cmd, None, OsStr::new(text))
            .map_err(|e| e.to_string())
    }

    #[test]
    fn names_and_parameters_parse_to_the_library_scheme() {
        assert_eq!(parse(Capability::Refine, "sqrt3").unwrap(), Scheme::Sqrt3);
        assert_eq!(
            parse(Capability::Refine, "butterfly:0.05").unwrap(),
            Scheme::Butterfly { tension: 0.05 }
        );
        let two_phase = parse(Capability::Interpolate, "two-phase:0.6").unwrap();
        assert_eq!(two_phase.two_phase().unwrap().uniform_lambda(), Some(0.6));
        assert!(
            !parse(Capability::Interpolate, "two-phase")
                .unwrap()
                .two_phase()
                .unwrap()
                .is_set()
        );
    }

    #[test]
    fn names_outside_the_command_and_bad_parameters_are_refused() {
        let e = parse(Capability::Evaluate, "sqrt3").unwrap_err();
        assert!(
            e.contains("'sqrt3'") && e.contains("catmull-clark, loop"),
            "{e}"
        );
        let e = parse(Capability::Refine, "butterfly:x").unwrap_err();
        assert!(
            e.contains("butterfly:x") && e.contains("not a finite number"),
            "{e}"
        );
        let e = parse(Capability::Refine, "loop:2").unwrap_err();
        assert!(e.contains("takes no parameter"), "{e}");
        // Each command's list, in the library's order.
        let names = |accepts| {
            parser(accepts)
                .accepted
                .iter()
                .map(Scheme::name)
                .collect::<Vec<_>>()
        };
        assert_eq!(names(Capability::Refine), Scheme::NAMES);
        assert_eq!(
            names(Capability::Limit),
            [
                "catmull-clark",
                "loop",
                "two-phase",
                "doo-sabin",
                "sqrt3",
                "butterfly",
                "modified-butterfly"
            ]
        );
        assert_eq!(
            names(Capability::Analyse),
            [
                "catmull-clark",
                "loop",
                "doo-sabin",
                "sqrt3",
                "butterfly",
                "modified-butterfly"
            ]
        );
        assert_eq!(names(Capability::Evaluate), ["catmull-clark", "loop"]);
        assert_eq!(
            names(Capability::Interpolate),
            ["catmull-clark", "loop", "two-phase"]
        );
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
