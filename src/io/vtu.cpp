#include "io/vtu.hpp"

#include <cstdint>
#include <cstring>

#include "core/error.hpp"
#include "io/output.hpp"

namespace shroudsim::io {
namespace {

std::string base64(const std::vector<std::uint8_t>& data) {
  static constexpr char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const std::uint32_t v = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += kTable[v & 63];
  }
  if (i < data.size()) {
    std::uint32_t v = data[i] << 16;
    if (i + 1 < data.size()) v |= data[i + 1] << 8;
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += i + 1 < data.size() ? kTable[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// VTK XML inline binary: a UInt32 byte count, then the data, base64-encoded together.
template <typename T>
std::string vtk_binary(const std::vector<T>& values) {
  const std::uint32_t bytes = static_cast<std::uint32_t>(values.size() * sizeof(T));
  std::vector<std::uint8_t> buf(sizeof bytes + bytes);
  std::memcpy(buf.data(), &bytes, sizeof bytes);
  if (bytes) std::memcpy(buf.data() + sizeof bytes, values.data(), bytes);
  return base64(buf);
}

}  // namespace

VtuBuilder::VtuBuilder(const mesh::Mesh& mesh) : mesh_(mesh) {
  s_ << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt32\">\n<UnstructuredGrid>\n<Piece NumberOfPoints=\""
     << mesh.n_nodes() << "\" NumberOfCells=\"" << mesh.n_elements() << "\">\n<PointData>\n";
}

void VtuBuilder::add(const std::string& name, const std::vector<float>& values, int components) {
  SHROUDSIM_CHECK(
      (components == 1 || components == 3) && values.size() == static_cast<std::size_t>(mesh_.n_nodes()) * components,
      "VtuBuilder::add: a field needs n_nodes * (1 or 3) values");
  s_ << "<DataArray type=\"Float32\" Name=\"" << name << "\" NumberOfComponents=\"" << components
     << "\" format=\"binary\">\n"
     << vtk_binary(values) << "\n</DataArray>\n";
}

std::string VtuBuilder::finish() {
  const mesh::Mesh& m = mesh_;
  const int npe = m.nodes_per_element();
  s_ << "</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">\n";
  std::vector<double> xyz(m.nodes.data(), m.nodes.data() + m.nodes.size());  // row-major n x 3
  s_ << vtk_binary(xyz) << "\n</DataArray>\n</Points>\n<Cells>\n";
  // VTK quadratic tetra: edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3); gmsh: ... (2,3) (1,3).
  static constexpr int kGmshToVtk10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
  std::vector<std::int32_t> conn, offsets;
  std::vector<std::uint8_t> types;
  for (int e = 0; e < m.n_elements(); ++e) {
    for (int a = 0; a < npe; ++a) conn.push_back(m.tets(e, npe == 10 ? kGmshToVtk10[a] : a));
    offsets.push_back(static_cast<std::int32_t>(conn.size()));
    types.push_back(npe == 10 ? 24 : 10);
  }
  s_ << "<DataArray type=\"Int32\" Name=\"connectivity\" format=\"binary\">\n"
     << vtk_binary(conn) << "\n</DataArray>\n"
     << "<DataArray type=\"Int32\" Name=\"offsets\" format=\"binary\">\n"
     << vtk_binary(offsets) << "\n</DataArray>\n"
     << "<DataArray type=\"UInt8\" Name=\"types\" format=\"binary\">\n"
     << vtk_binary(types) << "\n</DataArray>\n"
     << "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return s_.str();
}

void write_point_fields_vtu(const std::filesystem::path& path, const mesh::Mesh& mesh,
                            const std::vector<PointField>& fields) {
  VtuBuilder vtu(mesh);
  for (const auto& f : fields) {
    SHROUDSIM_CHECK(f.values.rows() == mesh.n_nodes() && (f.values.cols() == 1 || f.values.cols() == 3),
                    "write_point_fields_vtu: a field needs n_nodes rows and 1 or 3 columns");
    std::vector<float> v;
    v.reserve(f.values.size());
    for (Eigen::Index n = 0; n < f.values.rows(); ++n)
      for (Eigen::Index c = 0; c < f.values.cols(); ++c) v.push_back(static_cast<float>(f.values(n, c)));
    vtu.add(f.name, v, static_cast<int>(f.values.cols()));
  }
  write_file_atomic(path, vtu.finish());
}

}  // namespace shroudsim::io
