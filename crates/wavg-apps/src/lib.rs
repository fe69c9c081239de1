//! Applications of weighted averages on surfaces (paper Section 4), as library functions
//! over a [`wavg_solve::Solver`]: splines on surfaces (B-splines of any degree, open or
//! closed, and Bézier curves) whose samples are forward problems warm-started along the
//! curve.
#![forbid(unsafe_code)]
#![deny(unreachable_pub)]

mod basis;
mod spline;

pub use basis::{SplineKind, spline_weights};
pub use spline::{Curve, evaluate_spline};

mod error;
mod render;
mod transfer;

pub use error::AppError;
pub use render::{
    Camera, Colouring, FOV_DEGREES, Image, MAX_SIDE, Overlays, RenderOptions, View, render, viridis,
};
pub use transfer::{
    TextureTransfer, TransferOptions, check_uv, dilate, rasterize_uv, transfer_texture,
    transfer_texture_with_uv,
};
