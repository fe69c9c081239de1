//! Phong projection onto meshes embedded in R^8 (paper Sections 3.2-3.3).
