#![doc = include_str!("../README.md")]
#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

pub mod npy;
pub mod text;
