//! What an instance has to say to the importer's logger: the log categories switched on and
//! the lines queued until the call returns (the C layer hands them to the callback). The
//! first two categories of every model are its errors (always on) and warnings.

use crate::status::{FmiError, FmiResult, Status};

/// A line for the importer's logger.
#[derive(Clone, Debug, PartialEq)]
pub struct Message {
    pub status: Status,
    pub category: &'static str,
    pub text: String,
}

/// The log categories of a model (name, description), errors first, then warnings.
pub type Categories = &'static [(&'static str, &'static str)];

/// Index of the errors' category (always on) and of the warnings'.
pub const ERRORS: usize = 0;
pub const WARNINGS: usize = 1;

/// The categories switched on and the queued lines; not part of the FMU state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Log {
    categories: Categories,
    on: Vec<bool>,
    pub messages: Vec<Message>,
}

impl Log {
    /// Errors and warnings on; the other categories as `logging_on` says.
    pub fn new(categories: Categories, logging_on: bool) -> Self {
        let mut on = vec![logging_on; categories.len()];
        for flag in on.iter_mut().take(WARNINGS + 1) {
            *flag = true;
        }
        Log {
            categories,
            on,
            messages: Vec::new(),
        }
    }

    /// Whether a category is switched on.
    pub fn is_on(&self, category: usize) -> bool {
        self.on.get(category).copied().unwrap_or(false)
    }

    /// Queues a line for the logger if its category is on (errors always are).
    pub fn log(&mut self, status: Status, category: usize, text: impl FnOnce() -> String) {
        if self.is_on(category) {
            self.messages.push(Message {
                status,
                category: self.categories[category].0,
                text: text(),
            });
        }
    }

    /// Queues the reason of a refused or failed call.
    pub fn error(&mut self, error: &FmiError) {
        let category = if error.status <= Status::Warning {
            WARNINGS
        } else {
            ERRORS
        };
        self.log(error.status, category, || error.message.clone());
    }

    /// fmi2SetDebugLogging: the named categories (all when none is named) on or off; errors
    /// stay on. An unknown name refuses the whole call.
    pub fn set_debug_logging(&mut self, on: bool, names: &[String]) -> FmiResult {
        let mut indices = Vec::with_capacity(names.len());
        for name in names {
            match self.categories.iter().position(|(c, _)| c == name) {
                Some(i) => indices.push(i),
                None => {
                    let declared: Vec<_> = self.categories.iter().map(|(c, _)| *c).collect();
                    return Err(FmiError::error(format!(
                        "unknown log category \"{name}\"; declared: {}",
                        declared.join(", ")
                    )));
                }
            }
        }
        if indices.is_empty() {
            indices.extend(0..self.categories.len());
        }
        for i in indices {
            self.on[i] = on || i == ERRORS;
        }
        Ok(())
    }
}
