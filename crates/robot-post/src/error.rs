//! The one error type of the crate.

use crate::machine::MachineKind;

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
    /// The tool path is unreadable or holds non-finite numbers.
    #[error(transparent)]
    ToolPath(#[from] slicer::toolpath::ToolPathError),
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
}
