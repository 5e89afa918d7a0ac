//! The importer's logger: a C variadic function whose message is a printf format, so the
//! message is formatted here and every '%' escaped; the importer's componentEnvironment is
//! passed back untouched.

use crate::instance::Status;
use fmi_sys::fmi2::{
    fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2Status_fmi2Discard,
    fmi2Status_fmi2Error, fmi2Status_fmi2Fatal, fmi2Status_fmi2OK, fmi2Status_fmi2Warning,
};
use std::ffi::CString;

pub fn fmi2_status(status: Status) -> fmi2Status {
    match status {
        Status::Ok => fmi2Status_fmi2OK,
        Status::Warning => fmi2Status_fmi2Warning,
        Status::Discard => fmi2Status_fmi2Discard,
        Status::Error => fmi2Status_fmi2Error,
        Status::Fatal => fmi2Status_fmi2Fatal,
    }
}

/// A C string with interior NULs replaced, so that no message is ever lost.
pub fn c_string(text: &str) -> CString {
    CString::new(text.replace('\0', " ")).expect("no NUL left")
}

pub struct Logger {
    callback: fmi2CallbackLogger,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
}

impl Logger {
    pub fn new(
        callback: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
    ) -> Self {
        Logger {
            callback,
            environment,
            instance_name: c_string(instance_name),
        }
    }

    pub fn log(&self, status: Status, category: &str, text: &str) {
        let Some(callback) = self.callback else {
            return;
        };
        let message = c_string(&text.replace('%', "%%"));
        let category = c_string(category);
        // SAFETY: the importer gave this callback for this purpose; every string passed is a
        // valid NUL-terminated C string that outlives the call.
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
