//! How a command fails: an exit code and one line for stderr, and the checks every
//! command makes before it writes anything.

use crate::{EXIT_BAD_INPUT, EXIT_FAILURE};

/// A command's failure: exit code and one-line message.
#[derive(Debug)]
pub struct Failure {
    /// Process exit code.
    pub code: i32,
    /// One-line message (without the `subd: ` prefix).
    pub message: String,
}

impl From<subd_io::IoError> for Failure {
    fn from(e: subd_io::IoError) -> Self {
        let code = match &e {
            // The data cannot go into the format asked for (a PLY with UV seams): the
            // request is at fault, not the disk.
            subd_io::IoError::Write { source, .. }
                if source.kind() == std::io::ErrorKind::InvalidData =>
            {
                EXIT_BAD_INPUT
            }
            subd_io::IoError::Write { .. } => EXIT_FAILURE,
            _ => EXIT_BAD_INPUT,
        };
        Failure {
            code,
            message: e.to_string(),
        }
    }
}

/// Refuses an output path that names the input file.
pub(crate) fn refuse_overwrite(
    input: &std::path::Path,
    output: &std::path::Path,
) -> Result<(), Failure> {
    if let (Ok(a), Ok(b)) = (input.canonicalize(), output.canonicalize())
        && a == b
    {
        return Err(bad(format!(
            "{}: the output would overwrite the input",
            output.display()
        )));
    }
    Ok(())
}

pub(crate) fn bad(message: String) -> Failure {
    Failure {
        code: EXIT_BAD_INPUT,
        message,
    }
}
