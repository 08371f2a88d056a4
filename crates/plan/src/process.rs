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
}

impl Process {
    /// Reads a process file's text; the error names the line where the TOML is wrong.
    pub fn from_toml(text: &str) -> Result<Process, ProcessError> {
        toml::from_str(text).map_err(|e| {
            let line = e
                .span()
                .map(|r| text[..r.start.min(text.len())].matches('\n').count() + 1);
            let at = line.map(|l| format!(" line {l}")).unwrap_or_default();
            ProcessError(format!("process file{at}: {}", e.message().trim()))
        })
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
