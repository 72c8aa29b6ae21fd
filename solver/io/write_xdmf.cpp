// write_xdmf: the XDMF 3 sidecar that lets ParaView step through /steps/<k> of a result file: per step one grid
// per body and one for the contact surfaces of all pairs (the slave polylines with pressure, gap and active).
//
// Every attribute references a stored dataset whole: XDMF has no 2-component "Vector" (it means 3), so the
// multi-component arrays are declared "Matrix" (rows x components), which both of ParaView 5.11's XDMF readers
// (the default Xdmf3ReaderS and the XDMF 2 "XDMFReader") load with the right shape. HyperSlab items, which
// could cut ux and uy out as scalars, are dropped by the Xdmf3 reader ("unrecognized array type").
#include "contact/result_file.hpp"

#include "file_util.hpp"
#include "view_layout.hpp"
#include "xdmf_series.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace contact::io {

namespace {

std::string xml_escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (char ch : s) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

struct Writer {
  std::ostringstream out;
  std::string hdf;  // file name, escaped

  // <DataItem> reading the whole dataset `path` of `rows` x `cols` (cols 0 = 1-D).
  void data_item(const std::string& indent, const std::string& path, Eigen::Index rows, Eigen::Index cols,
                 const char* number_type, int precision) {
    out << indent << "<DataItem Dimensions=\"" << rows;
    if (cols > 0) out << ' ' << cols;
    out << "\" NumberType=\"" << number_type << "\" Precision=\"" << precision << "\" Format=\"HDF\">" << hdf << ':'
        << xml_escape(path) << "</DataItem>\n";
  }

  // An attribute read whole from the dataset `path` (cols 0 = 1-D). Multi-component arrays are "Matrix":
  // "Vector" means 3 components to ParaView's XDMF 2 reader, which garbles 2-component data.
  void attribute(const std::string& indent, const std::string& name, const char* center, const std::string& path,
                 Eigen::Index rows, Eigen::Index cols, const char* number_type = "Float", int precision = 8) {
    out << indent << "<Attribute Name=\"" << name << "\" AttributeType=\"" << (cols > 0 ? "Matrix" : "Scalar")
        << "\" Center=\"" << center << "\">\n";
    data_item(indent + "  ", path, rows, cols, number_type, precision);
    out << indent << "</Attribute>\n";
  }

  void body(const std::string& step_path, const BodyField& b) {
    const Eigen::Index n = b.mesh.num_nodes(), c = b.mesh.num_cells();
    if (c == 0) return;  // an empty grid would only confuse readers
    const std::string base = step_path + "/bodies/" + b.name;
    const std::string in = "        ";
    out << "      <Grid Name=\"" << xml_escape(b.name) << "\" GridType=\"Uniform\">\n";
    if (b.mesh.has_triangles()) {
      // XDMF's Mixed topology: per cell its type code (4 triangle, 5 quadrilateral) and its nodes.
      Eigen::Index length = 0;
      for (const auto& cell : b.mesh.cells) length += 1 + cell.size();
      out << in << "<Topology TopologyType=\"Mixed\" NumberOfElements=\"" << c << "\">\n";
      data_item(in + "  ", base + "/xdmf_topology", length, 0, "Int", 8);
    } else {
      out << in << "<Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"" << c << "\">\n";
      data_item(in + "  ", base + "/quads", c, 4, "Int", 8);
    }
    out << in << "</Topology>\n";
    out << in << "<Geometry GeometryType=\"XY\">\n";
    data_item(in + "  ", base + "/points", n, 2, "Float", 8);
    out << in << "</Geometry>\n";
    if (b.displacement.rows() == n) attribute(in, "displacement", "Node", base + "/displacement", n, 2);
    // The stresses as 6-component symmetric tensors: ParaView names their components XX, YY, ZZ, XY, YZ, XZ.
    if (b.stress_node.rows() == n) attribute(in, "stress_node", "Node", base + "/stress_node_tensor", n, 6);
    if (b.reaction.rows() == n) attribute(in, "reaction", "Node", base + "/reaction", n, 2);
    if (b.stress_cell.rows() == c) attribute(in, "stress_cell", "Cell", base + "/stress_cell_tensor", c, 6);
    if (b.von_mises_cell.rows() == c) attribute(in, "von_mises", "Cell", base + "/von_mises", c, 0);
    attribute(in, "level", "Cell", base + "/level", c, 0, "Int", 4);
    if (b.indicator_cell.rows() == c) attribute(in, "indicator", "Cell", base + "/indicator", c, 0);
    out << "      </Grid>\n";
  }

  // The contact surfaces of all pairs as one grid (the step's contact tables, contact_tables.hpp): the slave
  // polylines with the nodal pressure, gap, active flag and the pair's index in the step's pair_names (and with
  // friction the tangential traction, slip, stick flag and tangent). One grid, not one per pair: a wall of 4,129
  // bricks has 12,192 pairs, and whole datasets are all the Xdmf3 reader takes (no HyperSlab, above).
  void contacts(const std::string& step_path, const Step& s) {
    Eigen::Index n = 0, segments = 0;
    bool friction = false;
    for (const auto& p : s.pairs) {
      n += p.position.rows();
      segments += pair_segments(p.position.rows(), slave_is_closed(s, p)).rows();
      friction = friction || p.friction != "none";
    }
    if (segments == 0) return;
    const std::string base = step_path + "/contacts";
    const std::string in = "        ";
    out << "      <Grid Name=\"contacts\" GridType=\"Uniform\">\n";
    out << in << "<Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"" << segments << "\">\n";
    data_item(in + "  ", base + "/segments", segments, 2, "Int", 8);
    out << in << "</Topology>\n";
    out << in << "<Geometry GeometryType=\"XY\">\n";
    data_item(in + "  ", base + "/position", n, 2, "Float", 8);
    out << in << "</Geometry>\n";
    attribute(in, "pressure", "Node", base + "/pressure", n, 0);
    attribute(in, "gap", "Node", base + "/normal_gap", n, 0);
    attribute(in, "active", "Node", base + "/active", n, 0, "Int", 1);
    attribute(in, "pair", "Node", base + "/pair", n, 0, "Int", 4);
    if (friction) {  // friction: the tangential traction, the accumulated slip, stick and the tangent
      attribute(in, "tangential_traction", "Node", base + "/tangential_traction", n, 0);
      attribute(in, "slip", "Node", base + "/slip", n, 0);
      attribute(in, "stick", "Node", base + "/stick", n, 0, "Int", 1);
      attribute(in, "tangent", "Node", base + "/tangent", n, 2);
    }
    out << "      </Grid>\n";
  }
};

}  // namespace

std::string xdmf_path_for(const std::string& hdf_path) {
  const std::string ext = ".hdf";
  if (hdf_path.size() > ext.size() && hdf_path.compare(hdf_path.size() - ext.size(), ext.size(), ext) == 0)
    return hdf_path.substr(0, hdf_path.size() - ext.size()) + ".xmf";
  return hdf_path + ".xmf";
}

namespace detail {

XdmfSeries::XdmfSeries(std::string hdf_file_name) : hdf_(xml_escape(hdf_file_name)) {}

void XdmfSeries::add(const Step& step) {
  Writer w;
  w.hdf = hdf_;
  const std::string path = "/steps/" + std::to_string(grids_.size());
  for (const auto& b : step.bodies) w.body(path, b);
  w.contacts(path, step);
  grids_.push_back(w.out.str());
  load_factors_.push_back(step.load_factor);
}

void XdmfSeries::write(const std::string& xmf_path) const {
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<Xdmf Version=\"3.0\">\n"
      << "  <Domain>\n"
      << "    <Grid Name=\"steps\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  // Load steps are timed by their load factor (ParaView's time axis is then the load), when the factors
  // increase; adaptive steps (all at one load) by their index.
  bool by_load = grids_.size() > 1;
  for (size_t k = 1; k < grids_.size(); ++k) by_load = by_load && load_factors_[k] > load_factors_[k - 1];
  for (size_t k = 0; k < grids_.size(); ++k) {
    std::ostringstream time;
    time.precision(17);
    if (by_load)
      time << load_factors_[k];
    else
      time << k;
    out << "    <Grid Name=\"step " << k << "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
        << "      <Time Value=\"" << time.str() << "\"/>\n"
        << grids_[k] << "    </Grid>\n";
  }
  out << "    </Grid>\n"
      << "  </Domain>\n"
      << "</Xdmf>\n";
  const std::string text = out.str();
  write_atomically(xmf_path, "XDMF file", [&](const std::string& tmp) {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("cannot create '" + tmp + "': " + std::strerror(errno));
    f << text;
    f.close();
    if (!f) throw std::runtime_error("cannot write '" + tmp + "': " + std::strerror(errno));
  });
}

}  // namespace detail

void write_xdmf(const std::string& xmf_path, const std::string& hdf_file_name, const Result& result) {
  detail::XdmfSeries series(hdf_file_name);
  for (const auto& step : result.steps) series.add(step);
  series.write(xmf_path);
}

}  // namespace contact::io
