// Compares wavg with OpenMesh and Eigen on real meshes, printing one JSON object per mesh:
//
// * decimation to the same vertex count (1000): ours through the C interface, OpenMesh's
//   DecimaterT with ModQuadricT + ModNormalFlippingT (the same 45-degree bound as ours);
//   both scored the same way: sampled two-sided Hausdorff and mean distance to the
//   original over its bounding-box diagonal, flipped triangles (normal against the
//   nearest original triangle's), degenerate triangles, wall-clock seconds;
// * least-squares mesh: our landmarks and landmark coordinates, the bi-Laplacian energy
//   L M^-1 L assembled independently on OpenMesh's halfedge connectivity (cotangent
//   weights from each halfedge's opposite angle, lumped mass from vertex-face
//   circulators) and solved with Eigen's sparse Cholesky; the largest difference from our
//   embedding over its largest coordinate.
//
//   wavg_openmesh_harness [--target N] MESH...
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>

#include "distance.hpp"
#include "wavg.hpp"

namespace {

struct Traits : OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using Mesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;
using harness::Soup;
using harness::Vec3;

constexpr double kMaxNormalDeviationDeg = 45.0;  // ours (DecimateOptions' default)

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

Soup soup_of(const wavg::Surface &s) {
  Soup out;
  std::vector<double> xyz = s.positions();
  std::vector<uint32_t> tris = s.triangles();
  for (size_t i = 0; i < xyz.size(); i += 3) out.v.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  for (size_t i = 0; i < tris.size(); i += 3) out.f.push_back({tris[i], tris[i + 1], tris[i + 2]});
  return out;
}

Mesh openmesh_of(const Soup &s, size_t *rejected) {
  Mesh m;
  std::vector<Mesh::VertexHandle> vh;
  vh.reserve(s.v.size());
  for (const Vec3 &p : s.v) vh.push_back(m.add_vertex(Mesh::Point(p.x(), p.y(), p.z())));
  *rejected = 0;
  for (const auto &f : s.f)
    if (!m.add_face(vh[f[0]], vh[f[1]], vh[f[2]]).is_valid()) ++*rejected;
  return m;
}

Soup soup_of(const Mesh &m) {
  Soup out;
  for (auto v : m.vertices()) {
    const auto &p = m.point(v);
    out.v.emplace_back(p[0], p[1], p[2]);
  }
  for (auto f : m.faces()) {
    std::array<uint32_t, 3> t{};
    int c = 0;
    for (auto v : m.fv_range(f)) t[c++] = uint32_t(v.idx());
    out.f.push_back(t);
  }
  return out;
}

struct Score {
  double hausdorff, mean;
  size_t flipped, degenerate;
};

Score score(const Soup &fine, const harness::Bvh &fine_bvh, const Soup &coarse, double diag) {
  harness::Bvh coarse_bvh(coarse);
  harness::TwoSided d = harness::two_sided(fine, fine_bvh, coarse, coarse_bvh, 100000);
  Score s{d.hausdorff / diag, d.mean / diag, 0, 0};
  for (size_t t = 0; t < coarse.f.size(); t++) {
    Vec3 n = coarse.normal(t);
    if (0.5 * n.norm() <= 1e-12 * diag * diag) {
      s.degenerate++;
      continue;
    }
    Vec3 c = (coarse.corner(t, 0) + coarse.corner(t, 1) + coarse.corner(t, 2)) / 3.0;
    if (n.dot(fine.normal(fine_bvh.nearest(c).second)) < 0) s.flipped++;
  }
  return s;
}

/// OpenMesh's decimation of `m` (a copy) to `target` vertices.
Soup openmesh_decimate(Mesh m, size_t target, double *secs) {
  auto t0 = std::chrono::steady_clock::now();
  m.request_face_normals();
  m.update_face_normals();
  {
    OpenMesh::Decimater::DecimaterT<Mesh> dec(m);
    OpenMesh::Decimater::ModQuadricT<Mesh>::Handle quadric;
    OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle flipping;
    dec.add(quadric);
    dec.module(quadric).unset_max_err();
    dec.add(flipping);
    dec.module(flipping).set_max_normal_deviation(kMaxNormalDeviationDeg);
    if (!dec.initialize()) throw std::runtime_error("OpenMesh decimater did not initialise");
    dec.decimate_to(target);
    m.garbage_collection();  // while the decimater (and its status attributes) is alive
  }
  *secs = seconds_since(t0);
  return soup_of(m);
}

/// The least-squares mesh on OpenMesh's connectivity: every vertex's 8 coordinates with
/// the landmarks' fixed to `emb`. Returns max |ours - reference| / max |ours|.
double lsmesh_max_rel_diff(const Mesh &m, const std::vector<uint32_t> &landmarks,
                           const std::vector<double> &emb) {
  const int n = int(m.n_vertices());
  std::vector<Eigen::Triplet<double>> trip;
  for (auto h : m.halfedges()) {
    if (m.is_boundary(h)) continue;
    auto i = m.from_vertex_handle(h), j = m.to_vertex_handle(h);
    auto o = m.to_vertex_handle(m.next_halfedge_handle(h));
    auto pi = m.point(i), pj = m.point(j), po = m.point(o);
    auto e1 = pi - po, e2 = pj - po;
    double cross = OpenMesh::cross(e1, e2).norm();
    double w = cross > 0 ? 0.5 * OpenMesh::dot(e1, e2) / cross : 0.0;
    trip.emplace_back(i.idx(), j.idx(), -w);
    trip.emplace_back(j.idx(), i.idx(), -w);
    trip.emplace_back(i.idx(), i.idx(), w);
    trip.emplace_back(j.idx(), j.idx(), w);
  }
  Eigen::SparseMatrix<double> L(n, n);
  L.setFromTriplets(trip.begin(), trip.end());
  Eigen::VectorXd inv_mass(n);
  for (auto v : m.vertices()) {
    double area = 0;
    for (auto f : m.vf_range(v)) {
      auto it = m.cfv_begin(f);
      auto a = m.point(*it), b = m.point(*++it), c = m.point(*++it);
      area += 0.5 * OpenMesh::cross(b - a, c - a).norm();
    }
    inv_mass[v.idx()] = 3.0 / area;
  }
  Eigen::SparseMatrix<double> A = L * inv_mass.asDiagonal() * L;

  std::vector<int> fixed_index(n, -1), free_index(n, -1);
  for (size_t k = 0; k < landmarks.size(); k++) fixed_index[landmarks[k]] = int(k);
  int nf = 0;
  for (int v = 0; v < n; v++)
    if (fixed_index[v] < 0) free_index[v] = nf++;
  const int ns = int(landmarks.size());
  std::vector<Eigen::Triplet<double>> ff, fs;
  for (int col = 0; col < A.outerSize(); col++)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, col); it; ++it) {
      int r = int(it.row()), c = int(it.col());
      if (free_index[r] < 0) continue;
      if (free_index[c] >= 0) ff.emplace_back(free_index[r], free_index[c], it.value());
      else fs.emplace_back(free_index[r], fixed_index[c], it.value());
    }
  Eigen::SparseMatrix<double> Aff(nf, nf), Afs(nf, ns);
  Aff.setFromTriplets(ff.begin(), ff.end());
  Afs.setFromTriplets(fs.begin(), fs.end());
  Eigen::MatrixXd vs(ns, 8);
  for (int k = 0; k < ns; k++)
    for (int c = 0; c < 8; c++) vs(k, c) = emb[8 * landmarks[k] + c];
  Eigen::MatrixXd rhs = -(Afs * vs);
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(Aff);
  if (llt.info() != Eigen::Success) throw std::runtime_error("Eigen Cholesky failed");
  Eigen::MatrixXd vf = llt.solve(rhs);

  double max_diff = 0, max_coord = 0;
  for (int v = 0; v < n; v++)
    for (int c = 0; c < 8; c++) {
      double ours = emb[8 * v + c];
      double ref = free_index[v] >= 0 ? vf(free_index[v], c) : vs(fixed_index[v], c);
      max_diff = std::max(max_diff, std::abs(ours - ref));
      max_coord = std::max(max_coord, std::abs(ours));
    }
  return max_diff / max_coord;
}

void run(const std::string &path, size_t target) {
  wavg::Surface surface = wavg::Surface::open(path);
  Soup fine = soup_of(surface);
  harness::Bvh fine_bvh(fine);
  Vec3 lo = fine.v[0], hi = fine.v[0];
  for (const Vec3 &p : fine.v) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double diag = (hi - lo).norm();
  size_t rejected = 0;
  Mesh om = openmesh_of(fine, &rejected);
  if (rejected) throw std::runtime_error("OpenMesh rejected " + std::to_string(rejected) + " faces");

  auto t0 = std::chrono::steady_clock::now();
  wavg::Surface ours = surface.decimate(target);
  double ours_secs = seconds_since(t0);
  double om_secs = 0;
  Soup theirs = openmesh_decimate(om, target, &om_secs);
  Score so = score(fine, fine_bvh, soup_of(ours), diag);
  Score st = score(fine, fine_bvh, theirs, diag);

  t0 = std::chrono::steady_clock::now();
  surface.precompute();
  double precompute_secs = seconds_since(t0);
  double lsmesh = lsmesh_max_rel_diff(om, surface.landmarks(), surface.embedding());

  std::string name = path.substr(path.find_last_of('/') + 1);
  std::printf(
      "{\"mesh\": \"%s\", \"vertices\": %zu, \"target_vertices\": %zu, "
      "\"ours_vertices\": %zu, \"openmesh_vertices\": %zu, "
      "\"ours_hausdorff\": %.6g, \"openmesh_hausdorff\": %.6g, "
      "\"ours_mean_dist\": %.6g, \"openmesh_mean_dist\": %.6g, "
      "\"ours_seconds\": %.4f, \"openmesh_seconds\": %.4f, "
      "\"ours_flipped\": %zu, \"openmesh_flipped\": %zu, "
      "\"ours_degenerate\": %zu, \"openmesh_degenerate\": %zu, "
      "\"precompute_seconds\": %.3f, \"lsmesh_max_rel_diff\": %.3e}\n",
      name.c_str(), fine.v.size(), target, ours.vertex_count(), theirs.v.size(), so.hausdorff,
      st.hausdorff, so.mean, st.mean, ours_secs, om_secs, so.flipped, st.flipped,
      so.degenerate, st.degenerate, precompute_secs, lsmesh);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char **argv) try {
  size_t target = 1000;
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; i++) {
    std::string a = argv[i];
    if (a == "--target" && i + 1 < argc) target = std::strtoul(argv[++i], nullptr, 10);
    else meshes.push_back(a);
  }
  if (meshes.empty()) {
    std::cerr << "usage: wavg_openmesh_harness [--target N] MESH...\n";
    return 2;
  }
  for (const std::string &m : meshes) run(m, target);
  return 0;
} catch (const std::exception &e) {
  std::cerr << "wavg_openmesh_harness: " << e.what() << '\n';
  return 1;
}
