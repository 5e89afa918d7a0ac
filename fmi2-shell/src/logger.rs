//! The importer's logger callback, and FMI statuses as C values.

use crate::status::Status;
use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Discard,
    fmi2Status_fmi2Error, fmi2Status_fmi2Fatal, fmi2Status_fmi2OK, fmi2Status_fmi2Warning,
};
use std::ffi::{CStr, CString};

pub fn fmi2_status(status: Status) -> fmi2Status {
    match status {
        Status::Ok => fmi2Status_fmi2OK,
        Status::Warning => fmi2Status_fmi2Warning,
        Status::Discard => fmi2Status_fmi2Discard,
        Status::Error => fmi2Status_fmi2Error,
        Status::Fatal => fmi2Status_fmi2Fatal,
    }
}

/// A C string of `text`, NUL bytes replaced by spaces.
pub fn c_string(text: &str) -> CString {
    CString::new(text.replace('\0', " ")).expect("no NUL left")
}

/// The importer's logger, its environment and the instance's name.
pub struct Logger {
    callback: fmi2CallbackLogger,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
}

impl Logger {
    pub fn new(
        callback: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
        instance_name: &CStr,
    ) -> Self {
        Logger {
            callback,
            environment,
            instance_name: instance_name.to_owned(),
        }
    }

    /// Calls the logger, if there is one. The message is the format string of FMI's
    /// printf-like logger: its '%' are doubled, so an importer that formats it prints the
    /// text as it is, and one that does not shows '%%'.
    pub fn log(&self, status: Status, category: &str, text: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        let message = c_string(&text.replace('%', "%%"));
        let category = c_string(category);
        // SAFETY: the importer's callback with its environment and NUL-terminated strings
        // that live through the call.
        unsafe {
            callback(
                self.environment,
                self.instance_name.as_ptr(),
                fmi2_status(status),
                category.as_ptr(),
                message.as_ptr(),
            )
        }
    }
}
