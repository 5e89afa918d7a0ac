//! Statuses and errors of a call, in FMI's terms but free of C types.

/// The FMI status a call ends with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    Ok,
    Warning,
    Discard,
    Error,
    Fatal,
}

/// A refused or failed call: its status and the reason, for the log.
#[derive(Clone, Debug, PartialEq)]
pub struct FmiError {
    pub status: Status,
    pub message: String,
}

impl FmiError {
    pub fn error(message: impl Into<String>) -> Self {
        FmiError {
            status: Status::Error,
            message: message.into(),
        }
    }

    pub fn discard(message: impl Into<String>) -> Self {
        FmiError {
            status: Status::Discard,
            message: message.into(),
        }
    }
}

pub type FmiResult<T = ()> = Result<T, FmiError>;
