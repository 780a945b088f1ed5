//! Residual analysis of a fitted model: per channel, the RMS against the noise, where in time
//! the misfit sits (ejector stroke, interference zone, free flight), and whiteness
//! (autocorrelation against its 95 % band, and the Ljung-Box portmanteau test, G. M. Ljung and
//! G. E. P. Box, Biometrika 65, 1978); and the residual figures.

use std::path::Path;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Candidate, Job};
use sepval_common::propagator::{Observation, propagate};
use serde::{Deserialize, Serialize};

use super::DiagnoseError;
use sepval_fit::results::ChannelRms;
use sepval_fit::space::Noise;
use sepval_solve::lm::LmResult;
use sepval_solve::stats::{autocorrelation, ljung_box};

/// Family-wise level of the whiteness tests over the six channels: a channel is not white when
/// its Ljung-Box p-value is below `WHITENESS_P / 6` (Bonferroni), so that noise alone calls a
/// model's residuals coloured in at most 0.1 % of diagnoses.
pub const WHITENESS_P: f64 = 0.001;
/// Lags of the whiteness tests.
pub const LAGS: usize = 20;
/// Channel names and units.
pub const CHANNELS: [(&str, &str); 6] = [
    ("x", "m"),
    ("y", "m"),
    ("z", "m"),
    ("roll", "deg"),
    ("pitch", "deg"),
    ("yaw", "deg"),
];

/// Residual time segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SegmentRms {
    /// Segment name.
    pub name: String,
    /// Start \[s\] (first event).
    pub t_start_s: f64,
    /// End \[s\] (first event).
    pub t_end_s: f64,
    /// RMS residual in the segment, pooled over events (channel unit).
    pub rms: f64,
}

/// Residual analysis of one channel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelReport {
    /// Channel.
    pub channel: String,
    /// Unit.
    pub unit: String,
    /// RMS residual.
    pub rms: f64,
    /// Noise sigma.
    pub sigma: f64,
    /// RMS / sigma.
    pub rms_over_sigma: f64,
    /// RMS per time segment.
    pub segments: Vec<SegmentRms>,
    /// Fraction of autocorrelations at lags 1..20 outside the 95 % band +-1.96/sqrt(N).
    pub autocorr_outside_band: f64,
    /// Ljung-Box statistic (summed over events).
    pub ljung_box_q: f64,
    /// Its p-value.
    pub ljung_box_p: f64,
    /// Whether the residuals are white (p >= 0.001 / 6).
    pub white: bool,
}

/// Residual analysis of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResidualReport {
    /// Per channel.
    pub channels: Vec<ChannelReport>,
    /// Whether every channel is white.
    pub white: bool,
    /// Whether both goals are within 1.1 sigma.
    pub at_noise_floor: bool,
}

/// Residuals in physical units per event, per sample: (x, y, z \[m\], roll, pitch, yaw \[deg\]).
pub fn physical_residuals(r: &[f64], noise: Noise, events: &[usize]) -> Vec<Vec<[f64; 6]>> {
    let mut out = Vec::new();
    let mut pos = 0;
    for &n in events {
        out.push(
            (0..n)
                .map(|i| {
                    let s = &r[pos + 6 * i..pos + 6 * i + 6];
                    [
                        s[0] * noise.pos_m,
                        s[1] * noise.pos_m,
                        s[2] * noise.pos_m,
                        s[3] * noise.att_deg,
                        s[4] * noise.att_deg,
                        s[5] * noise.att_deg,
                    ]
                })
                .collect(),
        );
        pos += 6 * n;
    }
    out
}

/// RMS residual per channel, pooled over events.
pub fn rms_channels(res: &[Vec<[f64; 6]>]) -> ChannelRms {
    sepval_fit::results::channel_rms(res)
}

/// Time segments of the first event of the fitted model `c`: ejector stroke, interference zone
/// (until the decay factor falls below 0.1), free flight.
pub fn segments(job: &Job, c: &Candidate) -> Vec<(String, f64, f64)> {
    let e = &job.events()[0];
    let times = &e.data.times_s;
    let t_end = *times.last().unwrap_or(&0.0);
    let scenario = e.simulator.scenario();
    let decay = sepval_common::model::InterferenceDecay::new(
        scenario.interference.lambda_m,
        scenario.interference.s_end_m,
    );
    // Stroke end: the later foot of the baseline fit's own run.
    let stroke = e
        .simulator
        .simulate_logged(&c.factors, &EffectSet::NONE, &[times[0].max(0.0)])
        .ok()
        .and_then(|(_, log)| {
            log.foot_off_s
                .iter()
                .flatten()
                .cloned()
                .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.max(t))))
        })
        .unwrap_or(0.06);
    // The fitted model's own positions (it simulated when it was fitted; none, and the zone
    // runs to the end, if it does not now).
    let mut positions: Vec<Observation> = Vec::with_capacity(times.len());
    if let Ok(run) = c.run_setup(&e.simulator) {
        if propagate(e.simulator.model(), &run, times, &mut positions).is_err() {
            positions.clear();
        }
    }
    let zone_end = positions
        .iter()
        .zip(times)
        .find(|(o, t)| {
            **t > stroke
                && decay
                    .factor((o.pos_m[0].powi(2) + o.pos_m[1].powi(2) + o.pos_m[2].powi(2)).sqrt())
                    < 0.1
        })
        .map_or(t_end, |(_, t)| *t);
    vec![
        ("ejector stroke".into(), times[0], stroke.min(t_end)),
        ("interference zone".into(), stroke.min(t_end), zone_end),
        ("free flight".into(), zone_end, t_end),
    ]
}

/// The residual analysis of a refined fit (of the model `c`) against the noise and the floor.
pub fn residual_report(
    job: &Job,
    lm: &LmResult,
    c: &Candidate,
    noise: Noise,
    floor: [f64; 2],
) -> ResidualReport {
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let res = physical_residuals(&lm.residuals, noise, &events);
    let segs = segments(job, c);
    let mut channels = Vec::new();
    for (c, (name, unit)) in CHANNELS.iter().enumerate() {
        let sigma = if c < 3 { noise.pos_m } else { noise.att_deg };
        let all: Vec<f64> = res.iter().flatten().map(|s| s[c]).collect();
        let rms = (all.iter().map(|v| v * v).sum::<f64>() / all.len().max(1) as f64).sqrt();
        let segments = segs
            .iter()
            .map(|(n, t0, t1)| {
                let mut acc = (0.0, 0usize);
                for (ev, r) in job.events().iter().zip(&res) {
                    for (t, s) in ev.data.times_s.iter().zip(r) {
                        if *t >= *t0
                            && (*t < *t1 || (*t1 >= *ev.data.times_s.last().unwrap() && *t <= *t1))
                        {
                            acc.0 += s[c] * s[c];
                            acc.1 += 1;
                        }
                    }
                }
                SegmentRms {
                    name: n.clone(),
                    t_start_s: *t0,
                    t_end_s: *t1,
                    rms: if acc.1 > 0 {
                        (acc.0 / acc.1 as f64).sqrt()
                    } else {
                        0.0
                    },
                }
            })
            .collect();
        let (mut q, mut dof, mut outside, mut lags) = (0.0, 0usize, 0usize, 0usize);
        for r in &res {
            let x: Vec<f64> = r.iter().map(|s| s[c]).collect();
            let h = LAGS.min(x.len().saturating_sub(2)).max(1);
            let (qk, _) = ljung_box(&x, h);
            q += qk;
            dof += h;
            let band = 1.96 / (x.len() as f64).sqrt();
            let rho = autocorrelation(&x, h);
            outside += rho.iter().filter(|r| r.abs() > band).count();
            lags += h;
        }
        let p = sepval_solve::stats::chi2_sf(q, dof as f64);
        channels.push(ChannelReport {
            channel: name.to_string(),
            unit: unit.to_string(),
            rms,
            sigma,
            rms_over_sigma: rms / sigma,
            segments,
            autocorr_outside_band: outside as f64 / lags.max(1) as f64,
            ljung_box_q: q,
            ljung_box_p: p,
            white: p >= WHITENESS_P / CHANNELS.len() as f64,
        });
    }
    let white = channels.iter().all(|c| c.white);
    ResidualReport {
        channels,
        white,
        at_noise_floor: lm.goals.j_pos_m <= floor[0] && lm.goals.j_att_deg <= floor[1],
    }
}

/// Writes DIR/figures/residuals_eventK.png (baseline and extended residuals of each event).
pub fn residual_figures(
    dir: &Path,
    job: &Job,
    base: &LmResult,
    ext: &LmResult,
    noise: Noise,
    events: &[usize],
) -> Result<Vec<String>, DiagnoseError> {
    let b = physical_residuals(&base.residuals, noise, events);
    let e = physical_residuals(&ext.residuals, noise, events);
    let mut names = Vec::new();
    for (k, event) in job.events().iter().enumerate() {
        // A signal is observed before each figure (each is written whole or not at all).
        sepval_core::cancel::check().map_err(sepval_solve::run::RunError::from)?;
        let name = format!("figures/residuals_event{}.png", k + 1);
        sepval_report::figures::residual_figure(
            &dir.join(&name),
            &event.data.times_s,
            &[("baseline", &b[k]), ("extended", &e[k])],
            (noise.pos_m, noise.att_deg),
            &format!("Residuals (simulated - measured), {}", event.name),
        )?;
        names.push(name);
    }
    Ok(names)
}
