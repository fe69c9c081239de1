//! The cost of the C interface: `wavg_forward` / `wavg_inverse` of the built shared library
//! (loaded with `dlopen`, called through their C signatures) against the Rust batch calls
//! they wrap, on the same surface, anchors and queries, alternating in one process.
//!
//! ```text
//! cargo build --release -p wavg-ffi
//! cargo xtask lab abi_overhead \
//!     target/release/libwavg.so MESH [QUERIES=100000] [ROUNDS=5] [ANCHORS=32]
//! ```
//! Prints one line per operation: best-of-rounds milliseconds for Rust and for C, and
//! their ratio.

use std::ffi::{CString, c_char, c_void};
use std::time::Instant;

use wavg::{ForwardOptions, NoProgress, PrecomputeOptions, Surface, SurfacePoint};

#[repr(C)]
#[derive(Clone, Copy)]
struct CPoint {
    face: u32,
    bary: [f64; 3],
}

type Status = i32;
type OpenFn = unsafe extern "C" fn(*const c_char, *mut *mut c_void) -> Status;
type LoadFn = unsafe extern "C" fn(*mut c_void, *const c_char) -> Status;
type SolverNewFn =
    unsafe extern "C" fn(*const c_void, *const CPoint, usize, *mut *mut c_void) -> Status;
type ForwardFn = unsafe extern "C" fn(
    *const c_void,
    *const f64,
    usize,
    *mut CPoint,
    *mut f64,
    *mut Status,
) -> Status;
type InverseFn = unsafe extern "C" fn(
    *const c_void,
    *const CPoint,
    usize,
    bool,
    *mut f64,
    *mut Status,
) -> Status;

/// Looks a symbol up in the loaded library.
fn symbol<T: Copy>(lib: *mut c_void, name: &str) -> T {
    let c = CString::new(name).unwrap();
    // SAFETY: `lib` is a live dlopen handle and `c` a NUL-terminated name.
    let p = unsafe { libc::dlsym(lib, c.as_ptr()) };
    assert!(!p.is_null(), "{name} not found in the library");
    assert_eq!(std::mem::size_of::<T>(), std::mem::size_of::<*mut c_void>());
    // SAFETY: T is the function-pointer type of the symbol's C declaration.
    unsafe { std::mem::transmute_copy(&p) }
}

fn best_ms(rounds: usize, mut f: impl FnMut()) -> f64 {
    (0..rounds)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: abi_overhead LIBWAVG.so MESH [QUERIES] [ROUNDS] [ANCHORS]");
        std::process::exit(2);
    }
    let arg = |i: usize, d: usize| args.get(i).map_or(d, |s| s.parse().expect("a number"));
    let (n_queries, rounds, n_anchors) = (arg(2, 100_000), arg(3, 5), arg(4, 32));

    // The Rust side, and an embedding file for the C side to load (same embedding).
    let mut surface = Surface::open(&args[1]).expect("mesh");
    let opts = PrecomputeOptions {
        quality_pairs: 0,
        ..Default::default()
    };
    surface.precompute(&opts, &NoProgress).expect("precompute");
    let dir = std::env::temp_dir().join(format!("abi_overhead_{}.wavg", std::process::id()));
    surface.save_embedding(&dir).expect("save");
    // Anchors and points as ffi_tests/bench_abi.c makes them (same generator and seed),
    // so its C timings compare with these.
    let landmarks = surface.landmarks().to_vec();
    let anchors: Vec<wavg::Anchor> = (0..n_anchors)
        .map(|i| wavg::Anchor::Vertex(landmarks[i * landmarks.len() / n_anchors]))
        .collect();
    let solver = surface.solver(anchors.clone()).expect("solver");
    let nf = surface.n_faces() as f64;
    let mut state = 11u64;
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / 9007199254740992.0
    };
    let points: Vec<SurfacePoint> = (0..n_queries)
        .map(|_| {
            let f = (rnd() * nf) as u32;
            let (a, b, c) = (0.05 + rnd(), 0.05 + rnd(), 0.05 + rnd());
            let s = a + b + c;
            SurfacePoint::new(f, [a / s, b / s, 1.0 - a / s - b / s])
        })
        .collect();

    // The C side through the shared library.
    let lib_path = CString::new(args[0].as_str()).unwrap();
    // SAFETY: a NUL-terminated path; the library has no constructors with preconditions.
    let lib = unsafe { libc::dlopen(lib_path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    assert!(!lib.is_null(), "cannot dlopen {}", args[0]);
    let open: OpenFn = symbol(lib, "wavg_surface_open");
    let load: LoadFn = symbol(lib, "wavg_surface_load_embedding");
    let solver_new: SolverNewFn = symbol(lib, "wavg_solver_new");
    let forward: ForwardFn = symbol(lib, "wavg_forward");
    let inverse: InverseFn = symbol(lib, "wavg_inverse");
    let (mesh_c, emb_c) = (
        CString::new(args[1].as_str()).unwrap(),
        CString::new(dir.to_str().unwrap()).unwrap(),
    );
    let c_anchors: Vec<CPoint> = anchors
        .iter()
        .map(|a| {
            let wavg::Anchor::Vertex(v) = a else {
                unreachable!()
            };
            let p = surface.vertex_point(*v).unwrap();
            CPoint {
                face: p.face,
                bary: p.bary,
            }
        })
        .collect();
    let c_points: Vec<CPoint> = points
        .iter()
        .map(|p| CPoint {
            face: p.face,
            bary: p.bary,
        })
        .collect();
    let mut c_surface = std::ptr::null_mut();
    let mut c_solver = std::ptr::null_mut();
    // SAFETY: the C signatures above match include/wavg.h; buffers are sized as documented.
    unsafe {
        assert_eq!(open(mesh_c.as_ptr(), &mut c_surface), 0);
        assert_eq!(load(c_surface, emb_c.as_ptr()), 0);
        assert_eq!(
            solver_new(c_surface, c_anchors.as_ptr(), n_anchors, &mut c_solver),
            0
        );
    }
    let _ = std::fs::remove_file(&dir);

    // Weights for the forward problem: the inverse's, failed rows replaced by a vertex.
    let batch = solver.inverse_batch(&points);
    let mut weights = vec![0.0; n_queries * n_anchors];
    for (i, row) in weights.chunks_exact_mut(n_anchors).enumerate() {
        match batch.get(i) {
            Ok(w) => row.copy_from_slice(w),
            Err(_) => row[0] = 1.0,
        }
    }

    let mut c_w = vec![0.0; n_queries * n_anchors];
    let mut c_st = vec![0 as Status; n_queries];
    let mut c_out = vec![
        CPoint {
            face: 0,
            bary: [0.0; 3]
        };
        n_queries
    ];
    let mut c_xyz = vec![0.0; 3 * n_queries];
    let mut rust_batch = wavg::BatchWeights::default();
    let mut rust_trips = Vec::new();
    let tol = wavg::solve::DEFAULT_TOLERANCE;
    println!("queries {n_queries}, anchors {n_anchors}, best of {rounds} (alternating)");
    println!(
        "{:<18} {:>10} {:>10} {:>8}",
        "operation", "rust_ms", "c_abi_ms", "c/rust"
    );
    let report = |name: &str, rust: &mut dyn FnMut(), c: &mut dyn FnMut()| {
        let (mut r, mut cc) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..rounds {
            r = r.min(best_ms(1, &mut *rust));
            cc = cc.min(best_ms(1, &mut *c));
        }
        println!("{name:<18} {r:>10.2} {cc:>10.2} {:>8.3}", cc / r);
    };
    report(
        "forward",
        &mut || {
            let rows: Vec<&[f64]> = weights.chunks_exact(n_anchors).collect();
            std::hint::black_box(solver.forward_batch(&rows, &ForwardOptions::default()));
        },
        // SAFETY: as above.
        &mut || unsafe {
            forward(
                c_solver,
                weights.as_ptr(),
                n_queries,
                c_out.as_mut_ptr(),
                c_xyz.as_mut_ptr(),
                c_st.as_mut_ptr(),
            );
        },
    );
    report(
        "inverse",
        &mut || {
            let _ = solver.inverse_batch_into(&points, &mut rust_batch, wavg::solve::Par::Rayon);
        },
        // SAFETY: as above.
        &mut || unsafe {
            inverse(
                c_solver,
                c_points.as_ptr(),
                n_queries,
                false,
                c_w.as_mut_ptr(),
                c_st.as_mut_ptr(),
            );
        },
    );
    report(
        "inverse_verified",
        &mut || {
            let par = wavg::solve::Par::Rayon;
            // `Par::Rayon` always starts.
            let _ = solver.inverse_verified_batch_into(
                &points,
                tol,
                &mut rust_batch,
                &mut rust_trips,
                par,
            );
        },
        // SAFETY: as above.
        &mut || unsafe {
            inverse(
                c_solver,
                c_points.as_ptr(),
                n_queries,
                true,
                c_w.as_mut_ptr(),
                c_st.as_mut_ptr(),
            );
        },
    );
}
