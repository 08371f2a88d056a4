//! The settings of a plan: the process file and the machine profile with the `--set`
//! overrides, read and checked before any work, so that a bad one fails at once.

use crate::report::SettingsEntry;
use crate::Process;
use robot_post::machine::{MachineKind, MachineProfile};
use slicer::params::LayerParams;
use std::path::{Path, PathBuf};

/// Where a plan's settings come from (the command line's `--process`, `--machine`,
/// `--machine-profile` and `--set`).
#[derive(Debug, Clone, Default)]
pub struct Sources {
    /// The part (a bad feature parameter is reported against it when there is no process
    /// file).
    pub part: PathBuf,
    /// The process file; `None`: the defaults.
    pub process: Option<PathBuf>,
    /// A built-in machine's name; `None` (and no profile): `marlin`.
    pub machine: Option<String>,
    /// A machine profile file, instead of a built-in machine.
    pub machine_profile: Option<PathBuf>,
    /// `KEY=VALUE` overrides, in order.
    pub set: Vec<String>,
}

/// Why the settings could not be had: where (a file, `--set KEY=VALUE`, `--machine`) and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{origin}: {cause}")]
pub struct SettingsError {
    /// The file, the override or the option at fault.
    pub origin: String,
    /// What is wrong.
    pub cause: String,
}

impl SettingsError {
    fn new(origin: &Path, cause: impl std::fmt::Display) -> SettingsError {
        SettingsError {
            origin: origin.display().to_string(),
            cause: cause.to_string(),
        }
    }
}

type Failure = SettingsError;

/// The process file and the machine profile of a plan, with the `--set` overrides, checked,
/// in the order a user fixes them.
pub fn load(args: &Sources) -> Result<(Process, MachineProfile), SettingsError> {
    let settings = args.process.as_deref().unwrap_or(&args.part);
    let sets = args
        .set
        .iter()
        .map(|s| Set::parse(s))
        .collect::<Result<Vec<Set>, Failure>>()?;
    let process_text = match &args.process {
        Some(p) => std::fs::read_to_string(p)
            .map_err(|e| Failure::new(p, format!("cannot read process file: {e}")))?,
        None => String::new(),
    };
    // The file alone first, so that its own mistakes are reported against its lines.
    let mut process = Process::from_toml(&process_text).map_err(|e| {
        if looks_like_machine_profile(&process_text) {
            Failure::new(
                settings,
                "this is a machine profile (it has `kind` and `bed_size`), not a process file: give it with --machine-profile",
            )
        } else {
            Failure::new(settings, with_suggestion(&e.to_string()))
        }
    })?;
    let process_sets: Vec<&Set> = sets.iter().filter(|s| !s.machine).collect();
    if !process_sets.is_empty() {
        let mut table = process_text
            .parse::<toml::Table>()
            .map_err(|e| Failure::new(settings, e.message().trim()))?;
        for set in process_sets {
            set.apply(&mut table)?;
            let text = toml::to_string(&table).map_err(|e| set.failure(e))?;
            process = Process::from_toml(&text)
                .map_err(|e| set.failure(with_suggestion(&e.to_string())))?;
        }
    }
    process
        .validate_defaults()
        .map_err(|e| Failure::new(settings, e))?;
    let (machine_text, machine_source) = match (&args.machine_profile, args.machine.as_deref()) {
        (Some(p), _) => (
            std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read machine profile: {e}")))?,
            p.display().to_string(),
        ),
        (None, Some(name)) => {
            let kind = MachineKind::from_name(name).ok_or_else(|| {
                let hint = if name.ends_with(".toml") || std::path::Path::new(name).is_file() {
                    format!("`{name}` is a file: a machine profile goes to --machine-profile")
                } else {
                    format!("unknown machine `{name}`: the built-in ones are marlin, delta5 and kuka (a profile file goes to --machine-profile)")
                };
                SettingsError {
                    origin: "--machine".into(),
                    cause: hint,
                }
            })?;
            (
                MachineProfile::builtin_toml(kind).to_string(),
                format!("built-in {name}"),
            )
        }
        (None, None) => (
            MachineProfile::builtin_toml(MachineKind::Marlin).to_string(),
            "built-in marlin".into(),
        ),
    };
    let mut machine = MachineProfile::from_toml(&machine_text).map_err(|e| SettingsError {
        origin: machine_source.clone(),
        cause: with_suggestion(&e.to_string()),
    })?;
    let machine_sets: Vec<&Set> = sets.iter().filter(|s| s.machine).collect();
    if !machine_sets.is_empty() {
        let mut table = machine_text
            .parse::<toml::Table>()
            .map_err(|e| SettingsError {
                origin: machine_source.clone(),
                cause: e.message().trim().to_string(),
            })?;
        for set in machine_sets {
            set.apply(&mut table)?;
            let text = toml::to_string(&table).map_err(|e| set.failure(e))?;
            machine = MachineProfile::from_toml(&text)
                .map_err(|e| set.failure(with_suggestion(&e.to_string())))?;
        }
    }
    process
        .validate_orientation()
        .map_err(|e| Failure::new(settings, e))?;
    process
        .validate_for_nozzle(machine.nozzle_diameter)
        .map_err(|e| Failure::new(settings, e))?;
    Ok((process, machine))
}

/// The settings of a plan, every key: the process's defaults with `base`'s values, each
/// overridden feature's full parameters, the smoothing, and the machine profile.
pub fn entry(process: &Process, machine: &MachineProfile, base: &LayerParams) -> SettingsEntry {
    let json = |v: Result<serde_json::Value, serde_json::Error>| v.unwrap_or_default();
    let mut features = serde_json::Map::new();
    for (_, key) in process.feature_keys() {
        let p = base.patched(&process.features[key]);
        features.insert(key.clone(), json(serde_json::to_value(p)));
    }
    SettingsEntry {
        version: env!("CARGO_PKG_VERSION"),
        process: serde_json::json!({
            "defaults": json(serde_json::to_value(base)),
            "features": features,
            "orientation": json(serde_json::to_value(&process.orientation)),
        }),
        machine: json(serde_json::to_value(machine)),
    }
}

/// One `--set KEY=VALUE`: a process key (`uniform_layer_height` is `[defaults]`'s;
/// `features.2.perimeters`, `orientation.cone_angle_deg` name their table) or, after
/// `machine.`, a machine-profile key (`machine.nozzle_temperature`, `machine.delta5.z_min`).
/// The value is read as TOML (`0.1`, `true`, `[0, 0, 1]`, `"text"`), else taken as text
/// (`path_mode=contour`).
#[derive(Debug)]
struct Set {
    /// As given, for errors.
    given: String,
    machine: bool,
    /// The key's path of tables, the last one the key itself.
    path: Vec<String>,
    value: toml::Value,
}

impl Set {
    fn parse(given: &str) -> Result<Set, Failure> {
        let fail = |cause: &str| SettingsError {
            origin: format!("--set {given}"),
            cause: cause.to_string(),
        };
        let (key, value) = given
            .split_once('=')
            .ok_or_else(|| fail("expected KEY=VALUE, e.g. uniform_layer_height=0.1"))?;
        let mut path: Vec<String> = key
            .trim()
            .split('.')
            .map(|k| k.trim().to_string())
            .collect();
        if path.iter().any(|k| k.is_empty()) {
            return Err(fail("the key is empty or has an empty part"));
        }
        let machine = path[0] == "machine";
        if machine {
            path.remove(0);
            if path.is_empty() {
                return Err(fail(
                    "a machine key follows `machine.`, e.g. machine.nozzle_temperature=215",
                ));
            }
        } else if !matches!(path[0].as_str(), "defaults" | "features" | "orientation") {
            path.insert(0, "defaults".to_string());
        }
        let value = value.trim();
        let value = format!("v = {value}")
            .parse::<toml::Table>()
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(value.to_string()));
        Ok(Set {
            given: given.to_string(),
            machine,
            path,
            value,
        })
    }

    /// A failure of this override; a line number of the text it was merged into means nothing
    /// to the user, so it is left out.
    fn failure(&self, cause: impl std::fmt::Display) -> Failure {
        let mut cause = cause.to_string();
        for head in ["process file line ", "machine profile: line "] {
            if let Some(rest) = cause.strip_prefix(head) {
                if let Some((_, after)) = rest.split_once(": ") {
                    cause = after.to_string();
                }
            }
        }
        SettingsError {
            origin: format!("--set {}", self.given),
            cause,
        }
    }

    /// Puts the value into `table`, making the tables on its path.
    fn apply(&self, table: &mut toml::Table) -> Result<(), Failure> {
        let (last, tables) = self
            .path
            .split_last()
            .ok_or_else(|| self.failure("no key"))?;
        let mut t = table;
        for name in tables {
            let next = t
                .entry(name.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            t = next
                .as_table_mut()
                .ok_or_else(|| self.failure(format!("`{name}` is a value, not a table of keys")))?;
        }
        t.insert(last.clone(), self.value.clone());
        Ok(())
    }
}

/// Whether a TOML text is a machine profile (its top-level `kind` and `bed_size`).
fn looks_like_machine_profile(text: &str) -> bool {
    text.parse::<toml::Table>()
        .map(|t| t.contains_key("kind") && t.contains_key("bed_size"))
        .unwrap_or(false)
}

/// A settings error with an unknown key (`unknown field `x`, expected one of `a`, `b`, ...`)
/// gets the nearest known key suggested in place of the list, when one is close (at most a
/// third of its letters differ).
pub fn with_suggestion(message: &str) -> String {
    let Some(rest) = message.split("unknown field `").nth(1) else {
        return message.to_string();
    };
    let Some((typo, list)) = rest.split_once('`') else {
        return message.to_string();
    };
    let known: Vec<&str> = list.split('`').skip(1).step_by(2).collect();
    let best = known
        .iter()
        .map(|k| (edit_distance(typo, k), *k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d * 3 <= k.len().max(typo.len()) => {
            let head = &message[..message.len() - rest.len()];
            format!("{head}{typo}`: did you mean `{k}`?")
        }
        _ => message.to_string(),
    }
}

/// Levenshtein distance between two keys.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = if ca == *cb {
                prev
            } else {
                1 + prev.min(row[j]).min(row[j + 1])
            };
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::with_suggestion;

    #[test]
    fn a_misspelt_key_gets_the_nearest_one() {
        let m = "process file line 2: unknown field `uniform_layer_heigth`, expected one of `tolerance`, `uniform_layer_height`, `perimeters`";
        assert_eq!(
            with_suggestion(m),
            "process file line 2: unknown field `uniform_layer_heigth`: did you mean `uniform_layer_height`?"
        );
        // Nothing close: the list stays.
        let far = "unknown field `zzz`, expected one of `tolerance`, `perimeters`";
        assert_eq!(with_suggestion(far), far);
        assert_eq!(with_suggestion("other error"), "other error");
    }
}
