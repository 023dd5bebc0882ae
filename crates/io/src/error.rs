//! The error type of every reader and writer.

use std::path::PathBuf;

use subd_mesh::TopologyError;
use thiserror::Error;

/// A failure to read or write a mesh file. `Display` gives one line that names the file and,
/// for parse errors, the line (text formats) or the element (binary formats).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IoError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        /// File path.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The file could not be written.
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        /// File path.
        path: PathBuf,
        /// Underlying error.
        source: std::io::Error,
    },
    /// The extension names no format this operation supports.
    #[error("{}: unsupported file extension (expected {expected})", path.display())]
    UnknownFormat {
        /// File path.
        path: PathBuf,
        /// The extensions that would work.
        expected: &'static str,
    },
    /// A syntax error at a known line.
    #[error("{}:{line}: {message}", path.display())]
    Parse {
        /// File path.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A structural error without a single line (binary data, missing sections, empty file).
    #[error("{}: {message}", path.display())]
    Invalid {
        /// File path.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The faces, tags or coordinates do not make a valid mesh.
    #[error("{}: {source}", path.display())]
    Topology {
        /// File path.
        path: PathBuf,
        /// The topology error, naming the element.
        source: TopologyError,
    },
}

/// Errors a parser can return before a path is known: syntax or topology.
#[derive(Debug, Clone, PartialEq)]
pub enum ReadError {
    /// A syntax error, at a line when the format has lines.
    Syntax {
        /// 1-based line, if the format has lines.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// The topology is invalid.
    Topology(TopologyError),
}

impl std::fmt::Display for ReadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ReadError::Syntax {
                line: Some(l),
                message,
            } => write!(f, "line {l}: {message}"),
            ReadError::Syntax {
                line: None,
                message,
            } => f.write_str(message),
            ReadError::Topology(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ReadError {}

impl From<TopologyError> for ReadError {
    fn from(e: TopologyError) -> Self {
        ReadError::Topology(e)
    }
}

impl ReadError {
    /// A syntax error at a 1-based line.
    pub(crate) fn line(line: usize, message: impl Into<String>) -> Self {
        ReadError::Syntax {
            line: Some(line),
            message: message.into(),
        }
    }

    /// A syntax error not tied to a line.
    pub(crate) fn general(message: impl Into<String>) -> Self {
        ReadError::Syntax {
            line: None,
            message: message.into(),
        }
    }

    /// Attaches the file path.
    pub fn at(self, path: &std::path::Path) -> IoError {
        match self {
            ReadError::Syntax {
                line: Some(line),
                message,
            } => IoError::Parse {
                path: path.to_path_buf(),
                line,
                message,
            },
            ReadError::Syntax {
                line: None,
                message,
            } => IoError::Invalid {
                path: path.to_path_buf(),
                message,
            },
            ReadError::Topology(source) => IoError::Topology {
                path: path.to_path_buf(),
                source,
            },
        }
    }
}
