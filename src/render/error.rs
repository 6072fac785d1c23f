//! What a render can fail with: flags or a scene it cannot honour (a usage error: the command line exits 2), or
//! anything else (the device, a file: exit 1).

/// A render's failure. Not a `std::error::Error`, so that any error converts into it with `?` (as a failure) and
/// it converts into the command line's error by kind.
#[derive(Debug)]
pub enum RenderError {
    /// Flags, or flags and a scene, that cannot be rendered as asked; the message names the flag.
    Usage(String),
    Failure(anyhow::Error),
}

impl RenderError {
    /// The failure as one line.
    pub fn message(&self) -> String {
        match self {
            RenderError::Usage(m) => m.clone(),
            RenderError::Failure(e) => one_line(e),
        }
    }
}

/// An error and its causes on one line.
pub fn one_line(e: &anyhow::Error) -> String {
    format!("{e:#}").replace('\n', "; ")
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message())
    }
}

impl<E: Into<anyhow::Error>> From<E> for RenderError {
    fn from(e: E) -> Self {
        RenderError::Failure(e.into())
    }
}
