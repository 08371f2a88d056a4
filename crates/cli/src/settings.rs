//! The settings of `features plan`: the process file and the machine profile, read and checked
//! before any work, so that a bad one fails at once.

use crate::{Failure, PlanArgs};
use plan::Process;
use robot_post::machine::{MachineKind, MachineProfile};

/// The process file and the machine profile of a plan, checked, in the order a user fixes them.
pub fn settings(args: &PlanArgs) -> Result<(Process, MachineProfile), Failure> {
    let path = &args.part;
    let settings = args.process.as_deref().unwrap_or(path);
    let process = match &args.process {
        Some(p) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read process file: {e}")))?;
            Process::from_toml(&text).map_err(|e| {
                if looks_like_machine_profile(&text) {
                    Failure::new(
                        p,
                        "this is a machine profile (it has `kind` and `bed_size`), not a process file: give it with --machine-profile",
                    )
                } else {
                    Failure::new(p, with_suggestion(&e.to_string()))
                }
            })?
        }
        None => Process::default(),
    };
    process
        .validate_defaults()
        .map_err(|e| Failure::new(settings, e))?;
    let machine = match (&args.machine_profile, args.machine.as_deref()) {
        (Some(p), _) => {
            let text = std::fs::read_to_string(p)
                .map_err(|e| Failure::new(p, format!("cannot read machine profile: {e}")))?;
            MachineProfile::from_toml(&text)
                .map_err(|e| Failure::new(p, with_suggestion(&e.to_string())))?
        }
        (None, Some(name)) => MachineProfile::builtin(MachineKind::from_name(name).ok_or_else(
            || {
                let hint = if name.ends_with(".toml") || std::path::Path::new(name).is_file() {
                    format!("`{name}` is a file: a machine profile goes to --machine-profile")
                } else {
                    format!("unknown machine `{name}`: the built-in ones are marlin, delta5 and kuka (a profile file goes to --machine-profile)")
                };
                Failure {
                    path: "--machine".into(),
                    cause: hint,
                }
            },
        )?),
        (None, None) => MachineProfile::builtin(MachineKind::Marlin),
    };
    process
        .validate_orientation()
        .map_err(|e| Failure::new(settings, e))?;
    process
        .validate_for_nozzle(machine.nozzle_diameter)
        .map_err(|e| Failure::new(settings, e))?;
    Ok((process, machine))
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
