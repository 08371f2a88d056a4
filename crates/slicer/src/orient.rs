//! Tool-axis smoothing inside a tolerance cone (Chalvin et al. 2022, Eq. 3–7). Work in
//! progress: filled in by the orientation-smoothing work.
