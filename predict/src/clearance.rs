//! The clearance of a prediction (docs/envelope.md section 14.3): the distribution over the
//! samples of the smallest distance between the store and the aircraft, the probability that
//! it falls below the criterion (MIL-STD-1289D, "Airborne stores ejection clearance and
//! separation", asks for at least 25.4 mm), and when and where the store comes closest.
//!
//! Each sample's trajectory is the one its bands are made of without the measurement noise
//! (the noise is the instrument's, not the store's): y_s(t) + a_s delta(t), a_s the sample's
//! six standard normals on stream [`STREAM_BANDS`] (the first six draws of that stream, the
//! same as the bands'), delta the discrepancy. Its smallest clearance at the band's points is
//! [`sepval_geometry::Geometry::smallest`]; the smallest is taken once the store's CG has
//! moved the ejector stroke from carriage (docs/geometry.md). The samples are shared among
//! threads, each result in its sample's place, so the statistics are the same bits whatever
//! the thread count.
//!
//! A sample that diverged (the store tumbles within the record) has no trajectory: it is
//! counted apart, and the verdict counts it as a failure to clear ([`ClearanceStats::p_fail`]):
//! a release that tumbles has not separated cleanly.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use sepval_common::scenario::Scenario;
use sepval_core::cancel::{self, Cancelled};
use sepval_geometry::{Body, Geometry, GeometryError, Pose, Role};
use sepval_run::clearance::GeometryPaths;

use crate::bands::quantile;
use crate::sampling::{STREAM_BANDS, normal, sample_rng};
use crate::simulate::{Grid, GridTrajectory};

/// MIL-STD-1289D's smallest clearance between store and aircraft \[mm\] (1 in).
pub const DEFAULT_CRITERION_MM: f64 = 25.4;
/// The largest probability of failing to clear at which a condition is cleared: the
/// criterion must hold for 95 % of the samples.
pub const ALLOWED_PROBABILITY: f64 = 0.05;

/// The clearance to assess.
#[derive(Debug, Clone)]
pub struct ClearanceSettings {
    /// The store and the aircraft.
    pub geometry: Arc<Geometry>,
    /// The criterion \[m\].
    pub criterion_m: f64,
    /// The CG's travel from carriage after which the smallest clearance counts (the ejector's
    /// stroke) \[m\].
    pub free_after_m: f64,
}

/// The largest clearance criterion accepted \[mm\] (10 m: anything beyond is a unit mistake).
pub const MAX_CRITERION_MM: f64 = 10_000.0;

/// The geometry of a clearance that cannot be used; each names the flag it came from.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ClearanceInputError {
    /// A criterion out of range.
    #[error("--clearance-mm {mm}: expected a number of millimetres from 0 to {MAX_CRITERION_MM}")]
    Criterion {
        /// The criterion given \[mm\].
        mm: f64,
    },
    /// The aircraft's file.
    #[error("--aircraft {}", .path.display())]
    Aircraft {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: GeometryError,
    },
    /// The store's shape file.
    #[error("--store-shape {}", .path.display())]
    StoreShape {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: GeometryError,
    },
    /// The default store shape of the scenario's diameter.
    #[error("the default store shape, made of the scenario's store.diameter_m")]
    DefaultStore(#[source] GeometryError),
    /// The store and the aircraft together (the carriage check).
    #[error("--aircraft {} with the store {store}", .aircraft.display())]
    Together {
        /// The aircraft's file.
        aircraft: PathBuf,
        /// The store, as given.
        store: String,
        /// Why.
        #[source]
        source: GeometryError,
    },
}

impl ClearanceSettings {
    /// The settings of the geometry as given, for the store of `scenario`; `None` without an
    /// aircraft ([`ClearanceSettings::read`]).
    pub fn of(
        given: &GeometryPaths,
        scenario: &Scenario,
    ) -> Result<Option<ClearanceSettings>, ClearanceInputError> {
        let Some(aircraft) = &given.aircraft else {
            return Ok(None);
        };
        let store_shape = given.store_shape.as_deref();
        Self::read(aircraft, store_shape, given.clearance_mm, scenario).map(Some)
    }

    /// The clearance of the store of `scenario` (its shape from `store_shape`, or the default
    /// shape of its diameter) to the aircraft of the file `aircraft`, by `criterion_mm`: both
    /// read, and checked together at carriage (docs/geometry.md); a signal stops the reading.
    pub fn read(
        aircraft: &Path,
        store_shape: Option<&Path>,
        criterion_mm: f64,
        scenario: &Scenario,
    ) -> Result<ClearanceSettings, ClearanceInputError> {
        if !(0.0..=MAX_CRITERION_MM).contains(&criterion_mm) {
            return Err(ClearanceInputError::Criterion { mm: criterion_mm });
        }
        let stop = &cancel::requested;
        let plane = Body::read_until(aircraft, Role::Aircraft, stop).map_err(|source| {
            ClearanceInputError::Aircraft {
                path: aircraft.to_path_buf(),
                source,
            }
        })?;
        let store = match store_shape {
            Some(p) => Body::read_until(p, Role::Store, stop).map_err(|source| {
                ClearanceInputError::StoreShape {
                    path: p.to_path_buf(),
                    source,
                }
            })?,
            None => Body::default_store(scenario.store.diameter_m)
                .map_err(ClearanceInputError::DefaultStore)?,
        };
        let geometry = Geometry::new_until(store, plane, stop).map_err(|source| {
            ClearanceInputError::Together {
                aircraft: aircraft.to_path_buf(),
                store: store_shape.map_or("of the scenario (default shape)".into(), |p| {
                    p.display().to_string()
                }),
                source,
            }
        })?;
        Ok(ClearanceSettings {
            geometry: Arc::new(geometry),
            criterion_m: 1e-3 * criterion_mm,
            free_after_m: scenario.store.stroke_m,
        })
    }
}

/// Three percentiles of a quantity over the samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Percentiles {
    /// 5th.
    pub p5: f64,
    /// 50th.
    pub p50: f64,
    /// 95th.
    pub p95: f64,
}

impl Percentiles {
    /// The percentiles of `values` (type 7; NaN when empty).
    pub fn of(mut values: Vec<f64>) -> Percentiles {
        values.sort_by(f64::total_cmp);
        Percentiles {
            p5: quantile(&values, 0.05),
            p50: quantile(&values, 0.5),
            p95: quantile(&values, 0.95),
        }
    }
}

/// A pair of parts that comes closest, and in how many of the samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClosestParts {
    /// The store's part.
    pub store: String,
    /// The aircraft's part.
    pub aircraft: String,
    /// The share of the samples that ran whose closest approach is between these two.
    pub share: f64,
}

/// The clearance of a prediction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClearanceStats {
    /// The criterion \[mm\].
    pub criterion_mm: f64,
    /// Samples assessed (those that ran).
    pub samples: usize,
    /// Samples that diverged or failed.
    pub diverged: usize,
    /// The smallest clearance over the samples that ran \[mm\].
    pub min_clearance_mm: Percentiles,
    /// The share of the samples that ran whose smallest clearance is below the criterion.
    pub p_below: f64,
    /// The share of all samples that fail to clear: below the criterion or diverged.
    pub p_fail: f64,
    /// Whether the condition is cleared: `p_fail` at most [`ALLOWED_PROBABILITY`].
    pub cleared: bool,
    /// The share of the samples that ran that touch the aircraft (clearance 0).
    pub p_contact: f64,
    /// The time of closest approach \[s\].
    pub t_closest_s: Percentiles,
    /// The pairs of parts that come closest, most frequent first.
    pub closest_parts: Vec<ClosestParts>,
}

/// One sample's closest approach.
#[derive(Debug, Clone, Copy)]
struct SampleClosest {
    distance_m: f64,
    t_s: f64,
    parts: (usize, usize),
}

/// The clearance statistics of the samples (`samples[s]`: sample s's trajectory at the grid,
/// `None` when it did not run), each offset by its discrepancy deviation (module docs), on
/// `threads` threads. Every thread asks the cancellation flag before each pose it measures:
/// [`Cancelled`] within milliseconds of a signal, whatever the meshes.
pub fn assess(
    settings: &ClearanceSettings,
    samples: &[Option<&GridTrajectory>],
    discrepancy: &[[f64; 6]],
    grid: &Grid,
    seed: u64,
    threads: usize,
) -> Result<ClearanceStats, Cancelled> {
    assess_each(settings, samples, discrepancy, grid, seed, threads).map(|(stats, _)| stats)
}

/// [`assess`], with each sample's smallest clearance \[mm\] (`None`: it did not run or
/// cannot be placed), for a caller that groups the samples (the campaign's planning, by the
/// model each was drawn from).
pub fn assess_each(
    settings: &ClearanceSettings,
    samples: &[Option<&GridTrajectory>],
    discrepancy: &[[f64; 6]],
    grid: &Grid,
    seed: u64,
    threads: usize,
) -> Result<(ClearanceStats, Vec<Option<f64>>), Cancelled> {
    let n = samples.len();
    let chunk = n.div_ceil(threads.max(1)).max(1);
    let mut closest: Vec<Option<SampleClosest>> = vec![None; n];
    std::thread::scope(|scope| {
        for (c, out) in closest.chunks_mut(chunk).enumerate() {
            let start = c * chunk;
            scope.spawn(move || {
                for (k, slot) in out.iter_mut().enumerate() {
                    if cancel::requested() {
                        return;
                    }
                    let s = start + k;
                    *slot = samples[s].and_then(|t| {
                        sample_closest(settings, t, discrepancy, grid, seed, s as u64)
                    });
                }
            });
        }
    });
    // A sample stopped by the flag reads as one that did not run: nothing of it is kept.
    cancel::check()?;
    let each = closest
        .iter()
        .map(|c| c.map(|c| 1e3 * c.distance_m))
        .collect();
    Ok((stats(settings, &closest), each))
}

/// Sample `s`'s closest approach (`None` when its trajectory cannot be placed: a value that
/// is not finite, counted with the samples that diverged).
fn sample_closest(
    settings: &ClearanceSettings,
    trajectory: &GridTrajectory,
    discrepancy: &[[f64; 6]],
    grid: &Grid,
    seed: u64,
    s: u64,
) -> Option<SampleClosest> {
    let mut rng = sample_rng(seed, s, STREAM_BANDS);
    let a: [f64; 6] = std::array::from_fn(|_| normal(&mut rng));
    let poses: Vec<Pose> = trajectory
        .iter()
        .zip(discrepancy)
        .map(|(p, d)| {
            let v: [f64; 6] = std::array::from_fn(|c| p[c] + a[c] * d[c]);
            Pose {
                position_m: [v[0], v[1], v[2]],
                euler_deg: [v[3], v[4], v[5]],
            }
        })
        .collect();
    let trace = settings
        .geometry
        .smallest_until(&grid.t_s, &poses, settings.free_after_m, &cancel::requested)
        .ok()?;
    Some(SampleClosest {
        distance_m: trace.min.distance_m,
        t_s: trace.t_min_s,
        parts: (trace.min.store_part, trace.min.aircraft_part),
    })
}

/// The statistics of the samples' closest approaches.
fn stats(settings: &ClearanceSettings, closest: &[Option<SampleClosest>]) -> ClearanceStats {
    let ran: Vec<SampleClosest> = closest.iter().flatten().copied().collect();
    let (n, used) = (closest.len(), ran.len());
    let share = |k: usize, of: usize| {
        if of == 0 {
            f64::NAN
        } else {
            k as f64 / of as f64
        }
    };
    let below = ran
        .iter()
        .filter(|c| c.distance_m < settings.criterion_m)
        .count();
    let contact = ran.iter().filter(|c| c.distance_m <= 0.0).count();
    let diverged = n - used;
    let p_fail = share(below + diverged, n);
    let mut pairs: Vec<((usize, usize), usize)> = Vec::new();
    for c in &ran {
        match pairs.iter_mut().find(|(p, _)| *p == c.parts) {
            Some((_, k)) => *k += 1,
            None => pairs.push((c.parts, 1)),
        }
    }
    pairs.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let g = &settings.geometry;
    ClearanceStats {
        criterion_mm: 1e3 * settings.criterion_m,
        samples: used,
        diverged,
        min_clearance_mm: Percentiles::of(ran.iter().map(|c| 1e3 * c.distance_m).collect()),
        p_below: share(below, used),
        p_fail,
        cleared: p_fail <= ALLOWED_PROBABILITY,
        p_contact: share(contact, used),
        t_closest_s: Percentiles::of(ran.iter().map(|c| c.t_s).collect()),
        closest_parts: pairs
            .into_iter()
            .take(3)
            .map(|((s, a), k)| ClosestParts {
                store: g.store_part(s).to_string(),
                aircraft: g.aircraft_part(a).to_string(),
                share: share(k, used),
            })
            .collect(),
    }
}

/// The clearance in one sentence, verdict first.
pub fn words(c: &ClearanceStats) -> String {
    let pct = |p: f64| format!("{:.1} %", 100.0 * p);
    let m = &c.min_clearance_mm;
    let parts = c.closest_parts.first().map_or(String::new(), |p| {
        format!(
            ", most often between the store's {} and the aircraft's {} ({} of the samples)",
            p.store,
            p.aircraft,
            pct(p.share)
        )
    });
    let verdict = if c.cleared {
        format!(
            "Cleared: {} of the samples fail to keep {:.1} mm from the aircraft (at most {} allowed)",
            pct(c.p_fail),
            c.criterion_mm,
            pct(ALLOWED_PROBABILITY)
        )
    } else {
        format!(
            "Not cleared: {} of the samples fail to keep {:.1} mm from the aircraft (at most {} allowed)",
            pct(c.p_fail),
            c.criterion_mm,
            pct(ALLOWED_PROBABILITY)
        )
    };
    let diverged = match c.diverged {
        0 => String::new(),
        k => format!(" ({k} diverged, counted as failing)"),
    };
    format!(
        "{verdict}{diverged}. The smallest clearance is {:.0} mm (5th to 95th percentile {:.0} to {:.0} mm), at t = {:.3} s{parts}.",
        m.p50, m.p5, m.p95, c.t_closest_s.p50
    )
}
