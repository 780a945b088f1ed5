//! DIR/diagnosis.json as a record other commands read (`sepval plan`, `sepval predict`,
//! `sepval envelope`): written sealed with its digest and read through
//! [`sepval_run::sealed::read_record`], which checks what they read against its range.

use sepval_fit::result_check::check_rms;
use sepval_run::model_spec::ModelSpec;
use sepval_run::sealed::{
    FieldError, Record, check_factors, check_identifiability, check_noise, field,
};

use crate::{DIAGNOSIS_FORMAT, Diagnosis};

impl Record for Diagnosis {
    const FORMAT: &'static str = DIAGNOSIS_FORMAT;
    const COMMAND: &'static str = "diagnose";

    /// The noise, the answer's and each rival's model and BIC, the answer's residual RMS and the
    /// identifiability of its parameters.
    fn check(&self) -> Result<(), FieldError> {
        check_noise(self.sigma_pos_m, self.sigma_att_deg)?;
        check_model("model", &self.model)?;
        check_rms("extended.channel_rms", &self.extended.channel_rms)?;
        for (k, r) in self.rivals.iter().enumerate() {
            check_model(&format!("rivals[{k}].model"), &r.model)?;
            field(
                format!("rivals[{k}].delta_bic"),
                r.delta_bic,
                r.delta_bic.is_finite(),
                "a finite BIC difference",
            )?;
        }
        if let Some(i) = &self.identifiability {
            check_identifiability("identifiability", i)?;
        }
        Ok(())
    }
}

/// A model's factors, effect parameters and term coefficients: finite (the catalogue and the
/// term families check the rest when the model is rebuilt).
fn check_model(at: &str, m: &ModelSpec) -> Result<(), FieldError> {
    check_factors(&format!("{at}.factors"), &m.factors)?;
    for (k, e) in m.effects.iter().enumerate() {
        for (j, &v) in e.values.iter().enumerate() {
            field(
                format!("{at}.effects[{k}].values[{j}]"),
                v,
                v.is_finite(),
                "a finite parameter value",
            )?;
        }
    }
    for (k, t) in m.terms.iter().enumerate() {
        field(
            format!("{at}.terms[{k}].coefficient"),
            t.coefficient,
            t.coefficient.is_finite(),
            "a finite coefficient",
        )?;
    }
    Ok(())
}
