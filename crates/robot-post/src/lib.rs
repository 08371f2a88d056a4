//! robot-post: placeholder until its issue lands.
