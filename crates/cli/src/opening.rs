//! The opening every mesh command shares: the batch wrapper ([`Command::run`]), then per file
//! the timer, the overwrite and output-format checks ([`Command::start`]), the command's own
//! argument checks, and reading the input with its warnings printed ([`Started::read`]).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::batch::{self, Command, Files, Job, OutputFormat};
use crate::failure::{bad, refuse_overwrite};
use crate::rule_args::RuleArgs;
use crate::{Failure, print_warnings};

impl Command {
    /// Runs `one` on the single `IN OUT` pair of `files`, or on every input of a batch (see
    /// [`batch::run`]).
    pub(crate) fn run<F>(
        &self,
        files: &Files,
        json: bool,
        out: &mut dyn Write,
        err: &mut dyn Write,
        one: F,
    ) -> Result<(), Failure>
    where
        F: Fn(&Job, &mut dyn Write, &mut dyn Write) -> Result<(), Failure> + Sync,
    {
        batch::run(files, self, json, out, err, one)
    }

    /// [`Command::start`] for a job, which may name the USD prim to read.
    pub(crate) fn start_job(&self, job: &Job) -> Result<Started, Failure> {
        let mut started = self.start(&job.input, &job.output)?;
        started.prim = job.prim.clone();
        Ok(started)
    }

    /// Starts the command's timer and checks its output: it must not be the input, and its
    /// extension must be one of the command's formats.
    pub(crate) fn start(&self, input: &Path, output: &Path) -> Result<Started, Failure> {
        let started = Instant::now();
        refuse_overwrite(input, output)?;
        if !OutputFormat::of(output).is_some_and(|f| self.formats.contains(&f)) {
            return Err(bad(format!(
                "{}: unsupported output extension (expected {})",
                output.display(),
                extension_list(self.formats)
            )));
        }
        Ok(Started {
            input: input.to_path_buf(),
            started,
            prim: None,
        })
    }
}

/// `.obj, .ply or .glb`: the extensions of `formats`, for messages.
fn extension_list(formats: &[OutputFormat]) -> String {
    let names: Vec<String> = formats
        .iter()
        .map(|f| format!(".{}", f.extension()))
        .collect();
    match names.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// A command whose output passed its checks, before its input is read.
pub(crate) struct Started {
    input: PathBuf,
    started: Instant,
    /// The USD prim the batch picked for this job, over `--prim`.
    prim: Option<String>,
}

/// A command's input, read.
pub(crate) struct Opened {
    /// The mesh file.
    pub(crate) file: subd_io::MeshFile,
    /// When the command started.
    pub(crate) started: Instant,
    /// Seconds from the start to the end of reading.
    pub(crate) read_seconds: f64,
    /// How many of `file.warnings` are printed already.
    pub(crate) printed: usize,
}

impl Started {
    /// Reads the input with the rule arguments' read options and prints its warnings.
    pub(crate) fn read(self, rules: &RuleArgs, err: &mut dyn Write) -> Result<Opened, Failure> {
        self.read_with(&rules.read_options(), err)
    }

    /// Reads the input with `options` and prints its warnings.
    pub(crate) fn read_with(
        self,
        options: &subd_io::ReadOptions,
        err: &mut dyn Write,
    ) -> Result<Opened, Failure> {
        let file = match &self.prim {
            Some(prim) => {
                let options = subd_io::ReadOptions {
                    prim: Some(prim.clone()),
                    ..options.clone()
                };
                subd_io::read_mesh(&self.input, &options)?
            }
            None => subd_io::read_mesh(&self.input, options)?,
        };
        print_warnings(err, &self.input, &file.warnings);
        Ok(Opened {
            printed: file.warnings.len(),
            read_seconds: self.started.elapsed().as_secs_f64(),
            started: self.started,
            file,
        })
    }
}

impl Opened {
    /// Prints the warnings added to the file's since the last call (or since reading).
    pub(crate) fn print_new_warnings(&mut self, input: &Path, err: &mut dyn Write) {
        let from = self.printed.min(self.file.warnings.len());
        print_warnings(err, input, &self.file.warnings[from..]);
        self.printed = self.file.warnings.len();
    }

    /// Seconds since the command started.
    pub(crate) fn elapsed(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_lists_read_as_prose() {
        assert_eq!(
            extension_list(batch::MESH_OUTPUTS),
            ".obj, .ply, .glb, .usda, .usdc or .usdz"
        );
        assert_eq!(
            extension_list(&[OutputFormat::Txt, OutputFormat::Obj]),
            ".txt or .obj"
        );
        assert_eq!(extension_list(&[OutputFormat::Txt]), ".txt");
    }
}
