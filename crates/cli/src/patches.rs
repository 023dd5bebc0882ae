//! `subd patches`: the feature-adaptive patch table of a mesh (OpenSubdiv's
//! `RefineAdaptive` + `PatchTableFactory`), its census, and its arrays as JSON.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use subd_limit::patches::{EndCaps, MAX_ISOLATION, PatchOptions, PatchTable};
use subd_schemes::{Capability, Scheme};

use crate::choice_arg;
use crate::failure::{bad, refuse_overwrite};
use crate::rule_args::RuleArgs;
use crate::scheme_arg;
use crate::{Failure, print_warnings};

#[derive(Debug, Args)]
pub(crate) struct PatchesArgs {
    /// Subdivision scheme (default: the scheme the input names, USD's subdivisionScheme).
    #[arg(long, value_parser = scheme_arg::parser(Capability::Evaluate))]
    scheme: Option<Scheme>,
    #[command(flatten)]
    rules: RuleArgs,
    /// Levels of feature-adaptive refinement around irregular features (1 to 10).
    #[arg(long, default_value_t = MAX_ISOLATION,
          value_parser = clap::value_parser!(u8).range(1..=i64::from(MAX_ISOLATION)))]
    isolation: u8,
    /// How the irregular patches left at the isolation level are represented.
    #[arg(long, default_value = "gregory", value_parser = choice_arg::parser::<EndCaps>())]
    end_caps: EndCaps,
    /// Regular patches along one semi-sharp crease keep it instead of isolating it.
    #[arg(long)]
    single_crease: bool,
    /// Infinitely sharp features of regular topology become regular boundary patches.
    #[arg(long)]
    inf_sharp: bool,
    /// Smooth one-face corners are not approximated by sharp-corner patches.
    #[arg(long)]
    no_legacy_sharp_corners: bool,
    /// Input mesh.
    input: PathBuf,
    /// Output (.json): the table's arrays (see `subd_limit::patches::PatchTableLayout`), and
    /// with texture coordinates in the input their face-varying patches (`face_varying`).
    output: Option<PathBuf>,
    /// Print the census (patches by type, depth and boundary mask) on stdout as JSON.
    #[arg(long)]
    json: bool,
    /// Leave the input's texture coordinates out of the table (no face-varying patches).
    #[arg(long)]
    no_uv: bool,
}

impl PatchesArgs {
    fn options(&self) -> PatchOptions {
        PatchOptions {
            isolation: self.isolation,
            end_caps: self.end_caps,
            single_crease: self.single_crease,
            inf_sharp: self.inf_sharp,
            legacy_sharp_corners: !self.no_legacy_sharp_corners,
        }
    }
}

pub(crate) fn run(
    args: &PatchesArgs,
    out: &mut dyn Write,
    err: &mut dyn Write,
) -> Result<(), Failure> {
    if let Some(output) = &args.output {
        refuse_overwrite(&args.input, output)?;
        if output.extension().is_none_or(|e| e != "json") {
            return Err(bad(format!(
                "{}: the arrays are written as .json",
                output.display()
            )));
        }
    }
    let file = subd_io::read_mesh(&args.input, &args.rules.read_options())?;
    print_warnings(err, &args.input, &file.warnings);
    let rules = args.rules.options(&file.mesh.hints);
    let scheme = scheme_arg::given_or_named(
        args.scheme.as_ref(),
        &file.mesh.hints,
        Capability::Evaluate,
        &args.input,
    )?;
    let mut table = PatchTable::new(
        &file.mesh.topology,
        &file.mesh.positions,
        &scheme,
        &rules,
        &args.options(),
    )
    .map_err(|e| bad(format!("{}: {e}", args.input.display())))?;
    // Texture coordinates become the table's face-varying channel (OpenSubdiv's
    // generateFVarTables), refined with the file's or the command's interpolation mode.
    if let Some(uv) = file.mesh.uv().filter(|_| !args.no_uv) {
        let mode = args.rules.fvar_mode(&file.mesh.hints);
        table.add_face_varying(uv, mode).map_err(|e| {
            bad(format!(
                "{}: texture coordinates: {e}",
                args.input.display()
            ))
        })?;
    }
    if let Some(output) = &args.output {
        subd_io::atomic_write(output, |w| {
            serde_json::to_writer(&mut *w, &table.layout()).map_err(std::io::Error::other)?;
            writeln!(w)
        })?;
    }
    if args.json {
        crate::print_json(out, &table.census());
    }
    Ok(())
}

/// `--isolation` and `--end-caps` of `subd eval` and `subd tessellate`: given either, the
/// surface is the patch table's (OpenSubdiv's defaults otherwise); given neither, the exact
/// limit as before.
#[derive(Debug, Args)]
pub(crate) struct OnPatchesArgs {
    /// Evaluate on a patch table isolated this many levels (1 to 10; default 10 when
    /// --end-caps is given).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=i64::from(MAX_ISOLATION)))]
    isolation: Option<u8>,
    /// Evaluate on a patch table with these end caps (default: the exact limit).
    #[arg(long, value_parser = choice_arg::parser::<EndCaps>())]
    end_caps: Option<EndCaps>,
}

impl OnPatchesArgs {
    /// The patch options asked for, or `None` when none are (the exact limit's table).
    pub(crate) fn options(&self) -> Option<PatchOptions> {
        if self.isolation.is_none() && self.end_caps.is_none() {
            return None;
        }
        Some(PatchOptions {
            isolation: self.isolation.unwrap_or(MAX_ISOLATION),
            end_caps: self.end_caps.unwrap_or(EndCaps::Exact),
            ..Default::default()
        })
    }
}
