//! Closed surfaces made of tubes along a branching skeleton (generalised cylinders): each
//! limb is a run of vertex rings along a polyline, capped at its tip or split at its end
//! into child limbs. The connectivity depends only on the ring counts, the rows per
//! segment and the arcs of the splits, never on positions, so two skeletons with the same
//! counts give meshes with the same connectivity (vertex `i` of one corresponds to vertex
//! `i` of the other). Choices that look at positions (how rings of different counts are
//! zipped, where a split starts) are recorded on a tape by a reference skeleton and
//! replayed for the others, so they do not change the connectivity either.

use std::f64::consts::PI;

use nalgebra::{Rotation3, Vector3};

use crate::mesh::TriMesh;

type V3 = Vector3<f64>;

/// A point of a limb's skeleton: a ring centre, its radius and the rows of vertices from
/// the previous point to this one (the last row at this point).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Joint {
    pub at: V3,
    pub radius: f64,
    pub rows: usize,
}

/// A limb: its skeleton after the ring it starts from, the vertex count of its rings
/// (past the first row, which keeps its start ring's count) and, at its end, either a cap
/// (no children) or children, each taking `arc` edges of the end ring in turn, the
/// first centred on its first joint. A `relative` limb's joints are (outwards, sideways,
/// ahead) from the centre of its arc, outwards pointing from the end ring's centre.
#[derive(Clone, Debug)]
pub(crate) struct Limb {
    pub joints: Vec<Joint>,
    pub around: usize,
    pub children: Vec<(usize, Limb)>,
    pub relative: bool,
}

/// A ring of vertices with the frame its angles are measured in.
struct Ring {
    ids: Vec<u32>,
    center: V3,
    axis: V3,
    u: V3,
}

#[derive(Default)]
struct Builder {
    pos: Vec<V3>,
    tris: Vec<[u32; 3]>,
    tape: Vec<usize>,
    replay: Option<usize>,
}

/// The mesh of a skeleton: a cap at `tip`, then `root` (its first joint's ring is the
/// first ring, with `root.around` vertices), with the tape of its choices. With `tape`
/// (from a skeleton of the same counts) the choices are replayed.
pub(crate) fn build(tip: V3, root: &Limb, tape: Option<Vec<usize>>) -> (TriMesh, Vec<usize>) {
    let mut b = Builder {
        replay: tape.as_ref().map(|_| 0),
        tape: tape.unwrap_or_default(),
        ..Default::default()
    };
    let first = root.joints[0];
    let axis = (first.at - tip).normalize();
    let u = perpendicular(axis);
    let t = b.add(tip);
    let n = root.around;
    let angles: Vec<f64> = (0..n).map(|k| 2.0 * PI * k as f64 / n as f64).collect();
    let ring = b.ring(first.at, axis, u, first.radius, &angles);
    for k in 0..n {
        b.tris.push([t, ring.ids[(k + 1) % n], ring.ids[k]]);
    }
    let rest = Limb {
        joints: root.joints[1..].to_vec(),
        ..root.clone()
    };
    b.limb(ring, &rest);
    (TriMesh::new(b.pos, b.tris), b.tape)
}

/// `limb` with absolute joints: a relative limb's placed at `center` (its arc's centre)
/// in the frame (outwards from `hub`, sideways, `axis`).
fn placed(limb: &Limb, center: V3, hub: V3, axis: V3) -> Limb {
    if !limb.relative {
        return limb.clone();
    }
    let out = center - hub;
    let out = (out - axis * out.dot(&axis)).normalize();
    let side = axis.cross(&out);
    let joints = limb
        .joints
        .iter()
        .map(|j| Joint {
            at: center + j.at.x * out + j.at.y * side + j.at.z * axis,
            ..*j
        })
        .collect();
    Limb {
        joints,
        relative: false,
        ..limb.clone()
    }
}

/// A unit vector perpendicular to `a`.
fn perpendicular(a: V3) -> V3 {
    let other = if a.x.abs() < 0.9 { V3::x() } else { V3::y() };
    a.cross(&other).normalize()
}

/// `u` carried from a frame with axis `from` to one with axis `to` (minimal rotation).
fn transport(u: V3, from: V3, to: V3) -> V3 {
    let r = Rotation3::rotation_between(&from, &to).unwrap_or_else(Rotation3::identity);
    let u = r * u;
    let u = u - to * u.dot(&to);
    if u.norm() > 1e-9 {
        u.normalize()
    } else {
        perpendicular(to)
    }
}

impl Builder {
    /// `choose()`, or its recorded value when replaying.
    fn decide(&mut self, choose: impl FnOnce() -> usize) -> usize {
        match &mut self.replay {
            Some(i) => {
                *i += 1;
                self.tape[*i - 1]
            }
            None => {
                let c = choose();
                self.tape.push(c);
                c
            }
        }
    }

    fn add(&mut self, p: V3) -> u32 {
        self.pos.push(p);
        (self.pos.len() - 1) as u32
    }

    fn ring(&mut self, center: V3, axis: V3, u: V3, radius: f64, angles: &[f64]) -> Ring {
        let v = axis.cross(&u);
        let ids = angles
            .iter()
            .map(|a| self.add(center + radius * (a.cos() * u + a.sin() * v)))
            .collect();
        Ring {
            ids,
            center,
            axis,
            u,
        }
    }

    /// The angles of a ring's vertices around its axis, increasing from the first one's.
    fn angles(&self, r: &Ring) -> Vec<f64> {
        let v = r.axis.cross(&r.u);
        let mut out: Vec<f64> = Vec::with_capacity(r.ids.len());
        for &i in &r.ids {
            let d = self.pos[i as usize] - r.center;
            let mut a = d.dot(&v).atan2(d.dot(&r.u));
            if let Some(&prev) = out.last() {
                while a < prev {
                    a += 2.0 * PI;
                }
            }
            out.push(a);
        }
        out
    }

    /// Triangles between ring `a` (behind) and ring `b` (ahead), matched by angle.
    fn zip(&mut self, a: &Ring, fa: &[f64], b: &Ring, fb: &[f64]) {
        let (n, m) = (a.ids.len(), b.ids.len());
        let next = |f: &[f64], i: usize| if i + 1 < f.len() { f[i + 1] } else { 1.0 };
        let (mut i, mut j) = (0, 0);
        while i < n || j < m {
            let advance_a = if i == n || j == m {
                j == m
            } else {
                self.decide(|| usize::from(next(fa, i) <= next(fb, j))) == 1
            };
            if advance_a {
                self.tris.push([a.ids[i], a.ids[(i + 1) % n], b.ids[j % m]]);
                i += 1;
            } else {
                self.tris.push([a.ids[i % n], b.ids[(j + 1) % m], b.ids[j]]);
                j += 1;
            }
        }
    }

    /// The rings of `limb` after `start`, then its cap or its children.
    fn limb(&mut self, start: Ring, limb: &Limb) {
        let theta = self.angles(&start);
        let frac = |a: &[f64]| -> Vec<f64> { a.iter().map(|x| (x - a[0]) / (2.0 * PI)).collect() };
        let n0 = theta.len();
        let mut prev = start;
        let mut prev_frac = frac(&theta);
        let mut prev_radius = None;
        let mut first_row = true;
        for j in &limb.joints {
            let (c0, r0) = (prev.center, prev_radius.unwrap_or(j.radius));
            let axis = (j.at - c0).normalize();
            for row in 1..=j.rows {
                let s = row as f64 / j.rows as f64;
                let center = c0 + (j.at - c0) * s;
                let u = transport(prev.u, prev.axis, axis);
                let angles: Vec<f64> = if first_row {
                    (0..n0)
                        .map(|k| 0.5 * (theta[k] + theta[0] + 2.0 * PI * k as f64 / n0 as f64))
                        .collect()
                } else {
                    let n = limb.around;
                    (0..n)
                        .map(|k| theta[0] + 2.0 * PI * k as f64 / n as f64)
                        .collect()
                };
                first_row = false;
                let radius = r0 + (j.radius - r0) * s;
                let ring = self.ring(center, axis, u, radius, &angles);
                let f = frac(&angles);
                self.zip(&prev, &prev_frac, &ring, &f);
                prev = ring;
                prev_frac = f;
            }
            prev_radius = Some(j.radius);
        }
        let radius = prev_radius.unwrap_or(0.0);
        if limb.children.is_empty() {
            self.cap(&prev, &prev_frac, radius);
        } else {
            self.split(&prev, radius, &limb.children);
        }
    }

    /// A rounded cap: a smaller ring ahead of `end`, then a tip vertex.
    fn cap(&mut self, end: &Ring, f: &[f64], radius: f64) {
        let angles: Vec<f64> = f.iter().map(|x| x * 2.0 * PI).collect();
        let u = end.u;
        let inner = self.ring(
            end.center + end.axis * (0.6 * radius),
            end.axis,
            u,
            0.75 * radius,
            &angles,
        );
        self.zip(end, f, &inner, f);
        let tip = self.add(end.center + end.axis * radius);
        let n = inner.ids.len();
        for k in 0..n {
            self.tris.push([inner.ids[k], inner.ids[(k + 1) % n], tip]);
        }
    }

    /// Splits ring `end` into `children`: child `i` starts from its arc of the ring closed
    /// by a new centre vertex, the arcs in turn around the axis, the first centred on its
    /// child.
    fn split(&mut self, end: &Ring, radius: f64, children: &[(usize, Limb)]) {
        let n = end.ids.len();
        let v = end.axis.cross(&end.u);
        let angle_of = |p: V3| {
            let d = p - end.center;
            d.dot(&v).atan2(d.dot(&end.u)).rem_euclid(2.0 * PI)
        };
        let first = &children[0];
        let theta0 = self.angles(end)[0];
        let start = self.decide(|| {
            if first.1.relative {
                return 0;
            }
            let aim = (angle_of(first.1.joints[0].at) - theta0).rem_euclid(2.0 * PI);
            ((aim / (2.0 * PI) * n as f64).round() as isize - first.0 as isize / 2)
                .rem_euclid(n as isize) as usize
        });
        let mut start = start % n;
        let c = self.add(end.center + end.axis * (0.3 * radius));
        for (arc, child) in children {
            let mut ids: Vec<u32> = (0..=*arc).map(|k| end.ids[(start + k) % n]).collect();
            ids.push(c);
            start = (start + arc) % n;
            let center = ids.iter().map(|&i| self.pos[i as usize]).sum::<V3>() / ids.len() as f64;
            let child = &placed(child, center, end.center, end.axis);
            let axis = (child.joints[0].at - center).normalize();
            let u = transport(end.u, end.axis, axis);
            self.limb(
                Ring {
                    ids,
                    center,
                    axis,
                    u,
                },
                child,
            );
        }
    }
}
