//! The FMUs of the workspace that the packaging binary knows, by modelIdentifier: each
//! model's description from its own contract ([`crate::contracts`]), and its documentation.

use crate::{Model, contracts, documentation, gearbox_documentation};

/// GearRattle, with its documentation page and the work-precision plot.
pub fn gear_rattle() -> Model {
    use contracts::gear_rattle::{
        MODEL_DESCRIPTION_FMI3_XML, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER,
    };
    Model {
        identifier: MODEL_IDENTIFIER,
        library: "gear_rattle_fmu",
        model_description: MODEL_DESCRIPTION_XML,
        model_description_fmi3: Some(MODEL_DESCRIPTION_FMI3_XML),
        documentation: vec![
            ("index.html", documentation::index_html().into_bytes()),
            (
                "work_precision.png",
                documentation::WORK_PRECISION_PNG.to_vec(),
            ),
        ],
    }
}

/// GearboxRattle, with its documentation page.
pub fn gearbox_rattle() -> Model {
    use contracts::gearbox_rattle::{
        MODEL_DESCRIPTION_FMI3_XML, MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER,
    };
    Model {
        identifier: MODEL_IDENTIFIER,
        library: "gearbox_rattle_fmu",
        model_description: MODEL_DESCRIPTION_XML,
        model_description_fmi3: Some(MODEL_DESCRIPTION_FMI3_XML),
        documentation: vec![(
            "index.html",
            gearbox_documentation::index_html().into_bytes(),
        )],
    }
}

/// The drivetrain partner of the master tests (partners/flywheel), without documentation.
pub fn flywheel() -> Model {
    use contracts::flywheel::{MODEL_DESCRIPTION_XML, MODEL_IDENTIFIER};
    Model {
        identifier: MODEL_IDENTIFIER,
        library: "flywheel",
        model_description: MODEL_DESCRIPTION_XML,
        model_description_fmi3: None,
        documentation: Vec::new(),
    }
}

/// Every model, in the order the usage message lists them.
pub fn all() -> [Model; 3] {
    [gear_rattle(), gearbox_rattle(), flywheel()]
}
