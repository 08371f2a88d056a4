//! The one error type of the crate.

use crate::kind::MachineKind;

/// Why a profile, a tool path or a program could not be read or written. Every message is one
/// line, fit to follow `features: PATH: `.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PostError {
    /// The machine profile is not valid TOML or does not have the profile's keys.
    #[error("machine profile: {0}")]
    ProfileSyntax(String),
    /// A machine profile value is out of range.
    #[error("machine profile `{name}`: {field} {reason}")]
    ProfileValue {
        /// The profile's `name`.
        name: String,
        /// The offending key.
        field: &'static str,
        /// What is wrong with it, e.g. `must be positive, got -1`.
        reason: String,
    },
    /// The profile given to a post is for another kind of machine.
    #[error("machine profile `{name}` is for `{kind}`, not `{expected}`")]
    WrongMachine {
        /// The profile's `name`.
        name: String,
        /// The profile's kind.
        kind: MachineKind,
        /// The kind the post writes for.
        expected: MachineKind,
    },
    /// A program file could not be written where the post was told to write it.
    #[error("cannot write {name}: {reason}")]
    Write {
        /// The file's name.
        name: String,
        /// Why not.
        reason: String,
    },
    /// The tool path is unreadable or holds non-finite numbers.
    #[error(transparent)]
    ToolPath(#[from] toolpath::ToolPathError),
    /// A feature's tool axis is not one the machine can follow.
    #[error("feature {feature} has tool axis ({i:.6}, {j:.6}, {k:.6}), not +Z: `{machine}` prints only along +Z; it needs `delta5` or `kuka`")]
    ToolAxis {
        /// The feature's id.
        feature: usize,
        /// Tool axis X component.
        i: f64,
        /// Tool axis Y component.
        j: f64,
        /// Tool axis Z component.
        k: f64,
        /// The machine kind that refused it.
        machine: MachineKind,
    },
    /// The part (with its travel moves) is larger than the machine's bed.
    #[error("the path does not fit the {bed} mm bed of `{name}`: it overhangs by {excess}")]
    DoesNotFit {
        /// The profile's `name`.
        name: String,
        /// The bed size, `XxYxZ`.
        bed: String,
        /// By how much, per axis, e.g. `X 30.000 mm, Z 2.500 mm`.
        excess: String,
    },
    /// A tool axis the `delta5` bed cannot turn to machine +Z (beyond its B limits, or not a
    /// direction).
    #[error("feature {feature}: tool axis ({i:.6}, {j:.6}, {k:.6}) {reason} of `{name}`{remedy}")]
    Delta5Axis {
        /// The feature's id.
        feature: usize,
        /// Tool axis X component.
        i: f64,
        /// Tool axis Y component.
        j: f64,
        /// Tool axis Z component.
        k: f64,
        /// The profile's `name`.
        name: String,
        /// Why, e.g. `needs B 120.000 or -120.000 degrees, outside the B limits [-90, 90]`.
        reason: String,
        /// What would take it, after the profile's name (`: a machine with B up to 120
        /// degrees ...`), or nothing.
        remedy: String,
    },
    /// A path of a feature turns C further than the `delta5` profile's C limits allow.
    #[error("feature {feature}: C turns through {span:.3} degrees on one path, which does not fit the C limits [{c_min}, {c_max}] of `{name}` (c_continuous = true allows it)")]
    Delta5CLimits {
        /// The feature's id.
        feature: usize,
        /// The path's C span (degrees).
        span: f64,
        /// Lowest C (degrees).
        c_min: f64,
        /// Highest C (degrees).
        c_max: f64,
        /// The profile's `name`.
        name: String,
    },
    /// A move of a feature leaves the `delta5` machine's work envelope.
    #[error("feature {feature} leaves the work envelope of `{name}`: {excess}")]
    Delta5Envelope {
        /// The feature's id.
        feature: usize,
        /// The profile's `name`.
        name: String,
        /// Where and by how much, e.g. `Z -63.210 is 13.210 mm below -50.000`.
        excess: String,
    },
    /// A tool path point's tool axis is not a unit vector (KUKA post).
    #[error("tool path point {index} (feature {feature}): tool axis ({i:.6}, {j:.6}, {k:.6}) is not a unit vector")]
    KukaAxisNotUnit {
        /// Zero-based index of the point in the path.
        index: usize,
        /// The point's feature.
        feature: usize,
        /// Tool axis X component.
        i: f64,
        /// Tool axis Y component.
        j: f64,
        /// Tool axis Z component.
        k: f64,
    },
}
