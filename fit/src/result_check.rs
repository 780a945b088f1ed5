//! result.json as a sealed record (`sepval_run::sealed`): the ranges its reader checks, and the
//! check of a residual RMS per channel that diagnosis.json's reader shares.

use sepval_run::sealed::{
    FieldError, Record, check_factors, check_identifiability, check_noise, field,
};

use crate::results::{ChannelRms, FitResult, RESULT_FORMAT};

/// Checks a residual RMS per channel at `at`: finite and >= 0.
pub fn check_rms(at: &str, rms: &ChannelRms) -> Result<(), FieldError> {
    let names = ["x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"];
    for (name, v) in names.iter().zip(rms.as_array()) {
        field(
            format!("{at}.{name}"),
            v,
            v.is_finite() && v >= 0.0,
            "a finite RMS >= 0",
        )?;
    }
    Ok(())
}

impl Record for FitResult {
    const FORMAT: &'static str = RESULT_FORMAT;
    const COMMAND: &'static str = "fit";

    /// What `sepval predict` reads: the noise, each method's best (factors, weighted goal,
    /// residual RMS) and the identifiability.
    fn check(&self) -> Result<(), FieldError> {
        check_noise(self.sigma_pos_m, self.sigma_att_deg)?;
        for (name, m) in &self.methods {
            let at = format!("methods.{name}.best");
            check_factors(&format!("{at}.factors"), &m.best.factors)?;
            let w = m.best.weighted;
            field(
                format!("{at}.weighted"),
                w,
                w.is_finite() && w >= 0.0,
                "a finite weighted goal >= 0",
            )?;
            check_rms(&format!("{at}.channel_rms"), &m.best.channel_rms)?;
        }
        if let Some(i) = &self.identifiability {
            check_identifiability("identifiability", i)?;
        }
        Ok(())
    }
}
