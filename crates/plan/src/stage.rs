//! The stages of a plan, in the order [`crate::plan_into`] runs them, each a function in its own
//! module taking the previous stage's value and returning its own.

/// One stage of a plan ([`crate::Progress::Stage`] reports each as it begins).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    /// The STEP file read and parsed (the caller's: `brep::StepFile`).
    Read,
    /// The part stood on the plate ([`crate::place`]).
    Place,
    /// Its features recognised and ordered ([`crate::extract`]).
    Extract,
    /// Each feature's layers filled and laid, in parallel ([`crate::lay`]).
    Lay,
    /// The features' paths joined into one tool path, in build order ([`crate::lay`]).
    Sequence,
    /// Tool axes smoothed inside their tolerance cone ([`crate::smooth`]).
    Smooth,
    /// The print head against what is built and the table, with avoidance ([`crate::head`]).
    HeadCheck,
    /// What refuses a plan: self-check, collisions, reach, `--strict` ([`crate::gates`]).
    Gates,
    /// The machine program written ([`crate::post`]).
    Post,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 9] = [
        Stage::Read,
        Stage::Place,
        Stage::Extract,
        Stage::Lay,
        Stage::Sequence,
        Stage::Smooth,
        Stage::HeadCheck,
        Stage::Gates,
        Stage::Post,
    ];

    /// The stages after the features are laid that [`crate::Progress::Stage`] reports, in
    /// order: a progress display counts them with the features.
    pub const AFTER_FEATURES: [Stage; 3] = [Stage::Smooth, Stage::HeadCheck, Stage::Post];

    /// What a progress display says while it runs.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Read => "reading the part",
            Stage::Place => "placing the part",
            Stage::Extract => "recognising features",
            Stage::Lay => "laying the features",
            Stage::Sequence => "joining the features",
            Stage::Smooth => "smoothing tool axes",
            Stage::HeadCheck => "checking the print head",
            Stage::Gates => "checking the plan",
            Stage::Post => "writing the program",
        }
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
