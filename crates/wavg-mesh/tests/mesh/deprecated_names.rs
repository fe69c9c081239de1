//! The names from before validation "problems" became "defects" (deprecated aliases) still
//! name the same types, at the same paths.
#![allow(deprecated)]

use wavg_mesh::{
    Defect, DefectGroup, DefectKind, MeshInfo, Problem, ProblemGroup, ProblemKind, ProblemSummary,
    analyze, procedural,
};

#[test]
fn old_names_are_the_new_types() {
    let mut m = procedural::icosphere(0);
    let first = m.triangles[0];
    m.triangles.push(first);
    let a = analyze(&m);
    let p: &Problem = &a.report.problems[0];
    let d: &Defect = p;
    assert!(matches!(d, Problem::DuplicateFace { .. }));
    let k: ProblemKind = p.kind();
    assert_eq!(k, DefectKind::DuplicateFace);
    assert_eq!(ProblemKind::DuplicateFace.describe(), "duplicate faces");
    // A repeated face also makes its edges non-manifold: the summary lists those too.
    let s: Vec<ProblemSummary> = a.report.summary();
    let dup = s
        .iter()
        .find(|x| x.kind == DefectKind::DuplicateFace)
        .expect("the duplicate face is summarised");
    assert_eq!(dup.count, 1);
    let g: ProblemGroup = DefectGroup::from(dup);
    assert_eq!(g.remedy, Some("drop duplicate faces"));
    let info = MeshInfo::new(&m, None, &a);
    assert_eq!(info.problem_summary.len(), s.len());
    assert!(info.problem_summary.contains(&g));
}
