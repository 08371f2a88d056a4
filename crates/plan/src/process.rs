//! The process file: `[defaults]` layer parameters, `[features.<id>]` overrides and the
//! `[orientation]` smoothing (see `profiles/process.toml`).

use slicer::orient::SmoothParams;
use slicer::params::{LayerParams, LayerParamsPatch};
use std::collections::HashMap;

/// Why a process file was refused. The message is one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ProcessError(pub String);

/// A process file: `[defaults]` and `[features.<id>]` overrides, and tool-axis smoothing.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Process {
    /// Changes to the default layer parameters, for every feature.
    #[serde(default)]
    pub defaults: Option<LayerParamsPatch>,
    /// Changes for one feature, by its file-wide id.
    #[serde(default)]
    pub features: HashMap<String, LayerParamsPatch>,
    /// Tool-axis smoothing (Chalvin et al. 2022, Eq. 3–7).
    #[serde(default)]
    pub orientation: SmoothParams,
    /// Where each key was written: `(table, key)` → line, for errors that name the line.
    #[serde(skip)]
    lines: HashMap<(String, String), usize>,
}

/// Layer heights a machine can lay: at least this, mm.
pub const MIN_LAYER_HEIGHT: f64 = 0.05;
/// ... and at most this share of the nozzle's diameter.
pub const MAX_LAYER_HEIGHT_SHARE: f64 = 0.8;
/// Path spacing: within these shares of the nozzle's diameter.
pub const SPACING_SHARES: (f64, f64) = (0.5, 2.0);
/// Tolerance: at most this, mm.
pub const MAX_TOLERANCE: f64 = 1.0;

/// `(table, key)` → line of every `key = value` in a TOML text, by its lines (enough for
/// the flat tables of a process file).
fn key_lines(text: &str) -> HashMap<(String, String), usize> {
    let mut out = HashMap::new();
    let mut table = String::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if let Some(h) = l.strip_prefix('[') {
            table = h.split(']').next().unwrap_or("").trim().to_string();
            out.entry((table.clone(), String::new())).or_insert(i + 1);
        } else if let Some((k, _)) = l.split_once('=') {
            if !l.starts_with('#') {
                out.entry((table.clone(), k.trim().to_string()))
                    .or_insert(i + 1);
            }
        }
    }
    out
}

impl Process {
    /// Reads a process file's text; the error names the line where the TOML is wrong.
    /// A `[features.<id>]` table must name a feature by its whole-number id.
    pub fn from_toml(text: &str) -> Result<Process, ProcessError> {
        let mut process: Process = toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|r| text[..r.start.min(text.len())].matches('\n').count() + 1);
            let at = line.map(|l| format!(" line {l}")).unwrap_or_default();
            ProcessError(format!("process file{at}: {}", e.message().trim()))
        })?;
        process.lines = key_lines(text);
        let mut ids: Vec<&String> = process.features.keys().collect();
        ids.sort();
        for id in ids {
            if id.parse::<usize>().is_err() {
                return Err(ProcessError(format!(
                    "process file{}: [features.{id}]: a feature is named by its id, a whole number from 0 (`features extract` lists them)",
                    process.at("features", id, "")
                )));
            }
            let patch = &process.features[id];
            for (key, set) in [
                ("pedestal", patch.pedestal.is_some()),
                ("pedestal_inset", patch.pedestal_inset.is_some()),
                ("slicing", patch.slicing.is_some()),
                ("skirt_loops", patch.skirt_loops.is_some()),
                ("skirt_distance_mm", patch.skirt_distance_mm.is_some()),
                ("brim_width_mm", patch.brim_width_mm.is_some()),
                ("arc_fitting", patch.arc_fitting.is_some()),
            ] {
                if set {
                    return Err(ProcessError(format!(
                        "process file{}: [features.{id}] {key}: the {what} is the part's, not a feature's: set it in [defaults]",
                        process.at("features", id, key),
                        what = match key {
                            "slicing" => "slicing",
                            "pedestal" | "pedestal_inset" => "pedestal",
                            "arc_fitting" => "program's arc fitting",
                            _ => "skirt and brim",
                        },
                    )));
                }
            }
        }
        Ok(process)
    }

    /// ` line N` where `key` of table `[table.sub]` (or the table itself) was written.
    fn at(&self, table: &str, sub: &str, key: &str) -> String {
        let t = if sub.is_empty() {
            table.to_string()
        } else {
            format!("{table}.{sub}")
        };
        self.lines
            .get(&(t.clone(), key.to_string()))
            .or_else(|| self.lines.get(&(t, String::new())))
            .map(|l| format!(" line {l}"))
            .unwrap_or_default()
    }

    /// The `[features.<id>]` tables' keys with their ids, by id.
    pub fn feature_keys(&self) -> Vec<(usize, &String)> {
        let mut ids: Vec<(usize, &String)> = self
            .features
            .keys()
            .filter_map(|k| k.parse().ok().map(|n| (n, k)))
            .collect();
        ids.sort();
        ids
    }

    /// Checks that every `[features.<id>]` names one of the part's `count` features.
    pub fn validate_feature_ids(&self, count: usize) -> Result<(), ProcessError> {
        for (n, key) in self.feature_keys() {
            if n >= count {
                let have = match count {
                    0 => "no feature".to_string(),
                    1 => "one feature, id 0".to_string(),
                    c => format!("{c} features, ids 0 to {}", c - 1),
                };
                return Err(ProcessError(format!(
                    "process file{}: [features.{key}]: the part has {have}",
                    self.at("features", key, "")
                )));
            }
        }
        Ok(())
    }

    /// Checks the layer heights, path spacing and tolerance of `[defaults]` and of every
    /// `[features.<id>]` against a nozzle `nozzle` mm wide: heights within
    /// [[`MIN_LAYER_HEIGHT`], [`MAX_LAYER_HEIGHT_SHARE`] × nozzle], spacing within
    /// [`SPACING_SHARES`] × nozzle, tolerance at most [`MAX_TOLERANCE`]. The error names the
    /// table, key, value, line and range.
    pub fn validate_for_nozzle(&self, nozzle: f64) -> Result<(), ProcessError> {
        let base = self.base();
        let mut tables: Vec<(String, LayerParams)> = vec![("defaults".into(), base.clone())];
        for (_, id) in self.feature_keys() {
            tables.push((format!("features.{id}"), base.patched(&self.features[id])));
        }
        let h = (MIN_LAYER_HEIGHT, MAX_LAYER_HEIGHT_SHARE * nozzle);
        let w = (SPACING_SHARES.0 * nozzle, SPACING_SHARES.1 * nozzle);
        for (table, p) in &tables {
            let mut checks: Vec<(String, f64, (f64, f64), String)> = vec![];
            let why_h = format!(
                "{MIN_LAYER_HEIGHT} mm to {MAX_LAYER_HEIGHT_SHARE} x the {nozzle} mm nozzle"
            );
            let why_w = format!(
                "{} to {} x the {nozzle} mm nozzle",
                SPACING_SHARES.0, SPACING_SHARES.1
            );
            checks.push((
                "uniform_layer_height".into(),
                p.uniform_layer_height,
                h,
                why_h.clone(),
            ));
            for &a in &p.adaptive_layer_height {
                checks.push(("adaptive_layer_height".into(), a, h, why_h.clone()));
            }
            checks.push((
                "min_layer_height".into(),
                p.min_layer_height,
                h,
                why_h.clone(),
            ));
            checks.push((
                "max_layer_height".into(),
                p.max_layer_height,
                h,
                why_h.clone(),
            ));
            if let Some(o) = p.uniform_offset {
                checks.push(("uniform_offset".into(), o, w, why_w.clone()));
            }
            for &o in &p.adaptive_offset {
                checks.push(("adaptive_offset".into(), o, w, why_w.clone()));
            }
            checks.push((
                "tolerance".into(),
                p.tolerance,
                (0.0, MAX_TOLERANCE),
                format!("at most {MAX_TOLERANCE} mm"),
            ));
            for (key, v, (lo, hi), why) in checks {
                if !(v >= lo && v <= hi) {
                    let (t, sub) = table.split_once('.').unwrap_or((table.as_str(), ""));
                    return Err(ProcessError(format!(
                        "process file{}: [{table}] {key} = {v} is outside [{lo}, {hi:.3}] mm ({why})",
                        self.at(t, sub, &key)
                    )));
                }
            }
        }
        Ok(())
    }

    /// The layer parameters of every feature before its own overrides.
    pub fn base(&self) -> LayerParams {
        match &self.defaults {
            Some(p) => LayerParams::default().patched(p),
            None => LayerParams::default(),
        }
    }

    /// Checks `[defaults]`.
    pub fn validate_defaults(&self) -> Result<(), ProcessError> {
        self.base()
            .validate()
            .map_err(|e| ProcessError(format!("process defaults: {e}")))
    }

    /// Checks `[orientation]`.
    pub fn validate_orientation(&self) -> Result<(), ProcessError> {
        self.orientation
            .validate()
            .map_err(|e| ProcessError(format!("process [orientation]: {e}")))
    }

    /// The layer parameters of feature `f` of a tree whose features are numbered from
    /// `offset` in the file: [`Process::params_for`], with `base_allowance` the largest
    /// `machining_allowance` of the features it grows from (issue 37, item 2: it stands on
    /// their grown faces).
    pub fn feature_params(
        &self,
        base: &LayerParams,
        offset: usize,
        f: &features::Feature,
    ) -> Result<LayerParams, ProcessError> {
        let mut params = self.params_for(base, offset + f.id)?;
        for &p in &f.parents {
            let parent = self.params_for(base, offset + p)?.machining_allowance;
            params.base_allowance = params.base_allowance.max(parent);
        }
        Ok(params)
    }

    /// The layer parameters of feature `id` (file-wide): the defaults with its overrides,
    /// checked.
    pub fn params_for(&self, base: &LayerParams, id: usize) -> Result<LayerParams, ProcessError> {
        let params = match self.features.get(&id.to_string()) {
            Some(p) => base.patched(p),
            None => base.clone(),
        };
        params
            .validate()
            .map_err(|e| ProcessError(format!("feature {id}: {e}")))?;
        Ok(params)
    }
}
