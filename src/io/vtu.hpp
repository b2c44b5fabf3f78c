#pragma once
// VTK XML unstructured-grid files (.vtu) of a sector mesh with point data, for ParaView:
// inline binary (base64, UInt32 headers), Float32 point data, Float64 points, 4-node (VTK
// type 10) or 10-node (type 24, gmsh's edge order mapped to VTK's) tetrahedra.
//
//   io::VtuBuilder vtu(mesh);
//   vtu.add("displacement_m", values, 3);     // n_nodes * 3 floats, node-major
//   io::write_file_atomic(path, vtu.finish());
#include <Eigen/Core>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace shroudsim::io {

class VtuBuilder {
 public:
  explicit VtuBuilder(const mesh::Mesh& mesh);
  /// One point-data array: n_nodes * components values, node-major; components 1 or 3.
  void add(const std::string& name, const std::vector<float>& values, int components);
  /// The whole file (points and cells appended); the builder is spent afterwards.
  std::string finish();

 private:
  const mesh::Mesh& mesh_;
  std::ostringstream s_;
};

/// One point-data field: n_nodes rows, 1 (scalar) or 3 (vector) columns.
struct PointField {
  std::string name;
  Eigen::MatrixXd values;
};

/// `path` (written atomically): the mesh with the given fields (stored as Float32).
void write_point_fields_vtu(const std::filesystem::path& path, const mesh::Mesh& mesh,
                            const std::vector<PointField>& fields);

}  // namespace shroudsim::io
