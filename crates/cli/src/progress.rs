//! A spinner on stderr for work of unknown length, shown only on a terminal and never with
//! a JSON report (which owns stdout; a piped run stays quiet).

use std::borrow::Cow;
use std::io::IsTerminal;

/// A spinner with a message; nothing when stderr is not a terminal or JSON was asked for.
pub(crate) struct Spinner(Option<indicatif::ProgressBar>);

impl Spinner {
    pub(crate) fn new(json: bool, first: &'static str) -> Spinner {
        if json || !std::io::stderr().is_terminal() {
            return Spinner(None);
        }
        let bar = indicatif::ProgressBar::new_spinner();
        bar.set_message(first);
        bar.enable_steady_tick(std::time::Duration::from_millis(100));
        Spinner(Some(bar))
    }

    pub(crate) fn message(&self, m: impl Into<Cow<'static, str>>) {
        if let Some(b) = &self.0 {
            b.set_message(m);
        }
    }

    pub(crate) fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
