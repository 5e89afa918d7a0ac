//! The importer's logger callback (FMI 2.0's printf-like one or FMI 3.0's), and FMI statuses
//! as C values (FMI 3.0's are FMI 2.0's numbers).

use crate::status::Status;
use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Discard,
    fmi2Status_fmi2Error, fmi2Status_fmi2Fatal, fmi2Status_fmi2OK, fmi2Status_fmi2Warning,
};
use fmi_sys::fmi3::{fmi3InstanceEnvironment, fmi3LogMessageCallback};
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

/// The importer's logger callback of either edition.
enum Callback {
    /// FMI 2.0: the instance's name in each call, the message a printf format.
    Fmi2(fmi2CallbackLogger),
    /// FMI 3.0: the message as it is.
    Fmi3(fmi3LogMessageCallback),
}

/// The importer's logger, its environment and the instance's name.
pub struct Logger {
    callback: Callback,
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
            callback: Callback::Fmi2(callback),
            environment,
            instance_name: instance_name.to_owned(),
        }
    }

    /// FMI 3.0's logger (fmi3Instantiate*'s logMessage and instanceEnvironment).
    pub fn fmi3(
        callback: fmi3LogMessageCallback,
        environment: fmi3InstanceEnvironment,
        instance_name: &CStr,
    ) -> Self {
        Logger {
            callback: Callback::Fmi3(callback),
            environment,
            instance_name: instance_name.to_owned(),
        }
    }

    /// Calls the logger, if there is one. FMI 2.0's message is the format string of a
    /// printf-like logger: its '%' are doubled, so an importer that formats it prints the
    /// text as it is, and one that does not shows '%%'. FMI 3.0's is the text.
    pub fn log(&self, status: Status, category: &str, text: &str) {
        let category = c_string(category);
        let message = match self.callback {
            Callback::Fmi2(_) => c_string(&text.replace('%', "%%")),
            Callback::Fmi3(_) => c_string(text),
        };
        // SAFETY: the importer's callback with its environment and NUL-terminated strings
        // that live through the call.
        match self.callback {
            Callback::Fmi2(Some(callback)) => unsafe {
                callback(
                    self.environment,
                    self.instance_name.as_ptr(),
                    fmi2_status(status),
                    category.as_ptr(),
                    message.as_ptr(),
                )
            },
            Callback::Fmi3(Some(callback)) => unsafe {
                callback(
                    self.environment,
                    fmi2_status(status),
                    category.as_ptr(),
                    message.as_ptr(),
                )
            },
            Callback::Fmi2(None) | Callback::Fmi3(None) => {}
        }
    }
}
