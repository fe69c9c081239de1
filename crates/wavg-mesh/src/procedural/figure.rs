//! A human-like figure (head, torso, arms, five thin fingers per hand, legs) built from
//! tubes. Every [`FigureShape`] gives the same connectivity, so two shapes make a pair
//! with exact ground truth for correspondence tests: vertex `i` of one is vertex `i` of
//! the other.

use nalgebra::{Rotation3, Vector3};

use super::tubes::{Joint, Limb, build};
use crate::mesh::TriMesh;

type V3 = Vector3<f64>;

/// The body shape and pose of [`figure`] (lengths in metres of a figure about 1.8 tall).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FigureShape {
    /// Overall height scale (1 = 1.8 m).
    pub height: f64,
    /// Girth of the torso, arms and legs (1 = slim).
    pub girth: f64,
    /// Angle of the upper arms from the body, in radians.
    pub arm_spread: f64,
    /// Elbow bend (forward), in radians.
    pub elbow: f64,
    /// Angle of the legs from the vertical, in radians.
    pub leg_spread: f64,
    /// Finger length.
    pub finger_length: f64,
    /// Finger radius.
    pub finger_radius: f64,
}

impl FigureShape {
    /// A slim figure, arms out.
    pub const SLIM: Self = Self {
        height: 1.0,
        girth: 1.0,
        arm_spread: 0.6,
        elbow: 0.2,
        leg_spread: 0.08,
        finger_length: 0.08,
        finger_radius: 0.008,
    };
    /// A heavier, shorter figure with longer fingers, arms lower and bent, legs apart.
    pub const HEAVY: Self = Self {
        height: 0.92,
        girth: 1.45,
        arm_spread: 0.45,
        elbow: 0.7,
        leg_spread: 0.16,
        finger_length: 0.095,
        finger_radius: 0.011,
    };
    /// Arms well out and bent, thin fingers: a [`body`] whose hands an embedding
    /// extended between its landmarks squashes (the lab's `collapsed_pairs body:4`),
    /// the case the landmarks added around thin parts must handle.
    pub const SQUASHED_HANDS: Self = Self {
        height: 1.0315715517724773,
        girth: 0.9488724982957178,
        arm_spread: 0.7392461007790216,
        elbow: 0.6853653952523319,
        leg_spread: 0.0703057774264497,
        finger_length: 0.09589633727489663,
        finger_radius: 0.007367934190795696,
    };
}

fn j(x: f64, y: f64, z: f64, radius: f64, rows: usize) -> Joint {
    Joint {
        at: V3::new(x, y, z),
        radius,
        rows,
    }
}

/// A human-like figure of 4,000-odd vertices, standing along +z: genus 0, thin fingers
/// (8 vertices around), and the same connectivity for every shape.
///
/// ```
/// use wavg_mesh::procedural::{FigureShape, figure};
/// let (a, b) = (figure(&FigureShape::SLIM), figure(&FigureShape::HEAVY));
/// assert_eq!(a.triangles, b.triangles);
/// assert_ne!(a.positions, b.positions);
/// ```
pub fn figure(s: &FigureShape) -> TriMesh {
    shaped(s, false)
}

/// [`figure`] with ears and five toes per foot (5,000-odd vertices): more thin parts
/// that lie close to others (ears beside the head, toes beside each other), and again
/// the same connectivity for every shape.
///
/// ```
/// use wavg_mesh::procedural::{FigureShape, body, figure};
/// let (a, b) = (body(&FigureShape::SLIM), body(&FigureShape::HEAVY));
/// assert_eq!(a.triangles, b.triangles);
/// assert!(a.n_vertices() > figure(&FigureShape::SLIM).n_vertices());
/// ```
pub fn body(s: &FigureShape) -> TriMesh {
    shaped(s, true)
}

/// The figure of shape `s`, with ears and toes when `extremities`: the slim skeleton
/// records the connectivity's choices, `s`'s replays them.
fn shaped(s: &FigureShape, extremities: bool) -> TriMesh {
    let (_, tape) = build(TIP, &skeleton(&FigureShape::SLIM, extremities), None);
    let (mut mesh, _) = build(TIP, &skeleton(s, extremities), Some(tape));
    for p in &mut mesh.positions {
        *p *= s.height;
    }
    mesh
}

const TIP: V3 = V3::new(0.0, 0.0, 1.80);

/// Head and neck down to the shoulders, where the left arm splits off, then the right
/// arm, then the legs at the hips; with `extremities`, the ears split off the head and
/// the feet end in toes.
fn skeleton(s: &FigureShape, extremities: bool) -> Limb {
    let g = s.girth;
    let torso = Limb {
        joints: vec![
            j(0.0, 0.0, 1.05, 0.13 * g, 5),
            j(0.0, 0.0, 0.93, 0.15 * g, 3),
        ],
        around: 36,
        children: vec![
            (18, leg(s, -1.0, extremities)),
            (18, leg(s, 1.0, extremities)),
        ],
        relative: false,
    };
    let chest = Limb {
        joints: vec![j(0.0, 0.0, 1.27, 0.15 * g, 3)],
        around: 40,
        children: vec![(8, arm(s, 1.0)), (32, torso)],
        relative: false,
    };
    let neck = vec![
        j(0.0, 0.0, 1.53, 0.05, 3),
        j(0.0, 0.0, 1.47, 0.055, 2),
        j(0.0, 0.0, 1.40, 0.17 * g, 2),
    ];
    let shoulders = vec![(10, arm(s, -1.0)), (38, chest)];
    if !extremities {
        let mut joints = vec![j(0.0, 0.0, 1.74, 0.07, 2), j(0.0, 0.0, 1.63, 0.095, 3)];
        joints.extend(neck);
        return Limb {
            joints,
            around: 48,
            children: shoulders,
            relative: false,
        };
    }
    // Down to the ears' height, where the left ear splits off; a row lower the right.
    let lower = Limb {
        joints: neck,
        around: 48,
        children: shoulders,
        relative: false,
    };
    let right = Limb {
        joints: vec![j(0.0, 0.0, 1.60, 0.093, 2)],
        around: 48,
        children: vec![(6, ear(1.0)), (42, lower)],
        relative: false,
    };
    Limb {
        joints: vec![j(0.0, 0.0, 1.74, 0.07, 2), j(0.0, 0.0, 1.63, 0.095, 3)],
        around: 48,
        children: vec![(6, ear(-1.0)), (42, right)],
        relative: false,
    }
}

/// An ear on side `side` (-1 or 1): a short flat-ish tube out of the side of the head,
/// bent backwards and up, close to the head.
fn ear(side: f64) -> Limb {
    Limb {
        joints: vec![
            j(side * 0.105, -0.005, 1.615, 0.018, 2),
            j(side * 0.118, -0.02, 1.625, 0.016, 2),
            j(side * 0.122, -0.035, 1.64, 0.01, 2),
        ],
        around: 8,
        children: Vec::new(),
        relative: false,
    }
}

/// A leg on side `side` (-1 or 1), ending in a foot, with five toes when `toes`.
fn leg(s: &FigureShape, side: f64, toes: bool) -> Limb {
    let g = s.girth;
    let (sx, cz) = (s.leg_spread.sin(), s.leg_spread.cos());
    let hip = V3::new(side * 0.08 * g, 0.0, 0.86);
    let knee = hip + 0.40 * V3::new(side * sx, 0.0, -cz);
    let ankle = knee + 0.40 * V3::new(side * sx, 0.0, -cz);
    Limb {
        joints: vec![
            Joint {
                at: hip,
                radius: 0.075 * g,
                rows: 2,
            },
            Joint {
                at: knee,
                radius: 0.05 * g,
                rows: 8,
            },
            Joint {
                at: ankle,
                radius: 0.035 * g,
                rows: 8,
            },
            Joint {
                at: ankle + V3::new(0.0, 0.06, -0.05),
                radius: 0.04 * g,
                rows: 2,
            },
            Joint {
                at: ankle + V3::new(0.0, 0.16, -0.07),
                radius: 0.03 * g,
                rows: 3,
            },
        ],
        around: 24,
        children: if toes {
            [4, 5, 5, 5, 5].map(|arc| (arc, toe(s))).to_vec()
        } else {
            Vec::new()
        },
        relative: false,
    }
}

/// A toe: a short tube ahead of its arc of the foot's end, spreading a little outwards.
fn toe(s: &FigureShape) -> Limb {
    let radius = 0.7 * s.finger_radius;
    Limb {
        joints: (0..=2)
            .map(|k| {
                let t = 0.008 + 0.012 * k as f64;
                j(0.2 * t, 0.0, t, radius * (1.0 - 0.1 * k as f64), 2)
            })
            .collect(),
        around: 8,
        children: Vec::new(),
        relative: true,
    }
}

/// An arm on side `side` (-1 or 1): upper arm, forearm bent forward at the elbow, palm,
/// five fingers.
fn arm(s: &FigureShape, side: f64) -> Limb {
    let g = s.girth;
    let shoulder = V3::new(side * 0.2 * g, 0.0, 1.36);
    let upper = V3::new(side * s.arm_spread.sin(), 0.0, -s.arm_spread.cos());
    let elbow = shoulder + 0.28 * upper;
    let fore = Rotation3::from_axis_angle(&V3::x_axis(), s.elbow) * upper;
    let wrist = elbow + 0.26 * fore;
    let palm = wrist + 0.06 * fore;
    // Relative to each finger's arc of the palm: (outwards, sideways, ahead).
    let step = s.finger_length / 3.0;
    let finger = Limb {
        joints: (0..=3)
            .map(|k| {
                let t = 0.01 + step * k as f64;
                j(0.3 * t, 0.0, t, s.finger_radius * (1.0 - 0.1 * k as f64), 3)
            })
            .collect(),
        around: 8,
        children: Vec::new(),
        relative: true,
    };
    Limb {
        joints: vec![
            Joint {
                at: shoulder,
                radius: 0.05 * g,
                rows: 2,
            },
            Joint {
                at: elbow,
                radius: 0.04 * g,
                rows: 6,
            },
            Joint {
                at: wrist,
                radius: 0.03 * g,
                rows: 6,
            },
            Joint {
                at: palm,
                radius: 0.04 * g,
                rows: 2,
            },
        ],
        around: 30,
        children: vec![(6, finger); 5],
        relative: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ValidMesh, analyze};

    #[test]
    fn every_shape_is_a_closed_oriented_genus_0_surface() {
        let shapes = [FigureShape::SLIM, FigureShape::HEAVY];
        for m in shapes.iter().flat_map(|s| [figure(s), body(s)]) {
            let a = analyze(&m);
            let st = a.stats;
            assert!(st.manifold && st.oriented && st.watertight, "{st:?}");
            assert_eq!((st.components, st.genus), (1, Some(0)), "{st:?}");
            assert!(a.report.is_valid(), "{:?}", a.report);
            // Outward: positive enclosed volume.
            let vol = super::super::enclosed_volume(&m);
            assert!(vol > 0.0, "volume {vol}");
            ValidMesh::new(m).unwrap();
        }
    }
}
