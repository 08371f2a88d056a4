//! Freeform features: offset reference-surface layers, spatial slicing, paths on curved
//! layers. Work in progress.
