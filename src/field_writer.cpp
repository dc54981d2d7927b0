// Parallel HDF5 field output with an XDMF index; see field_writer.hpp.
//
// All HDF5 metadata operations (creating groups, datasets, attributes) are
// collective in parallel HDF5, so every rank must make the same calls in the
// same order with the same names and shapes. Argument checks are therefore
// agreed on over the communicator before any HDF5 call: a bad argument on one
// rank makes every rank throw instead of leaving the others waiting in a
// collective call.
#include "field_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace capstan {
namespace {

// Closes an HDF5 handle on scope exit, so an exception never leaks one.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Throws on every rank if any rank has a non-empty `error`; the message is the
// local one where there is one, so the rank with the bad input names it.
void agree(MPI_Comm comm, const std::string& error) {
  int bad = error.empty() ? 0 : 1, anyBad = 0;
  MPI_Allreduce(&bad, &anyBad, 1, MPI_INT, MPI_MAX, comm);
  if (anyBad) throw std::runtime_error(bad ? error : "FieldWriter: another rank reported an error");
}

bool validName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

// Shortest text that reads back as the same double (0.1, not 0.10000000000000001).
std::string exact(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v).ptr);
}

const char* attributeType(int components) {
  switch (components) {
    case 1: return "Scalar";
    case 3: return "Vector";
    case 6: return "Tensor6";  // VTK order xx yy zz xy yz xz, as in the header
    default: return "Matrix";
  }
}

using FieldShapes = std::vector<std::pair<std::string, int>>;  // name, components

struct StepRecord {
  std::string group;  // "/steps/000042"
  double time;
  FieldShapes nodal, elements, faces;
};

}  // namespace

struct FieldWriter::Impl {
  MPI_Comm comm;
  int rank = 0;
  long long nodeOffset, nodesOwned, nodesGlobal;
  long long elemOffset, elemsOwned, elemsGlobal;
  long long faceOffset, facesOwned, facesGlobal;
  std::string directory, h5Path;
  hid_t file = -1;
  std::vector<StepRecord> steps;

  void check(bool ok, const std::string& what) const {
    if (!ok) throw std::runtime_error("FieldWriter: " + h5Path + ": " + what);
  }

  // Collectively creates dataset `path` [global, components] and writes this
  // rank's rows [offset, offset + owned) from `data`.
  void writeRows(const std::string& path, hid_t memType, hid_t fileType, long long offset,
                 long long owned, long long global, int components, const void* data) const {
    const hsize_t fileDims[2] = {hsize_t(global), hsize_t(components)};
    Handle fileSpace(H5Screate_simple(2, fileDims, nullptr), H5Sclose);
    check(fileSpace >= 0, "cannot create dataspace for " + path);
    Handle dset(H5Dcreate2(file, path.c_str(), fileType, fileSpace, H5P_DEFAULT, H5P_DEFAULT,
                           H5P_DEFAULT),
                H5Dclose);
    check(dset >= 0, "cannot create dataset " + path);

    // A rank without rows still joins the collective write, selecting nothing.
    // Its memory space gets one row (so no zero-sized dataspace is needed) and
    // a dummy buffer (older HDF5 releases reject a null one).
    const hsize_t memDims[2] = {hsize_t(std::max(owned, 1LL)), hsize_t(components)};
    Handle memSpace(H5Screate_simple(2, memDims, nullptr), H5Sclose);
    check(memSpace >= 0, "cannot create memory dataspace for " + path);
    static const double dummy[1] = {0.0};
    if (owned > 0) {
      const hsize_t start[2] = {hsize_t(offset), 0};
      const hsize_t count[2] = {hsize_t(owned), hsize_t(components)};
      check(H5Sselect_hyperslab(fileSpace, H5S_SELECT_SET, start, nullptr, count, nullptr) >= 0,
            "cannot select rows of " + path);
    } else {
      check(H5Sselect_none(fileSpace) >= 0 && H5Sselect_none(memSpace) >= 0,
            "cannot select nothing in " + path);
      data = dummy;
    }
    Handle dxpl(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
    check(dxpl >= 0 && (alone() || H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) >= 0),
          "cannot set collective transfer for " + path);
    check(H5Dwrite(dset, memType, memSpace, fileSpace, dxpl, data) >= 0,
          "cannot write dataset " + path);
  }

  void writeDoubles(const std::string& path, long long offset, long long owned, long long global,
                    int components, const std::vector<double>& values) const {
    writeRows(path, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, offset, owned, global, components,
              values.data());
  }

  void makeGroup(const std::string& path) const {
    Handle g(H5Gcreate2(file, path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    check(g >= 0, "cannot create group " + path);
  }

  // Layout checks shared by both constructors (collective).
  void init(const std::string& directory, const FieldLayout& layout);
  // One rank: HDF5's plain POSIX driver (MPI-IO's opens shared-memory
  // files, a semaphore and a lock test per open: G1 1x's output 10 -> 7 ms).
  bool alone() const {
    int size = 0;
    MPI_Comm_size(comm, &size);
    return size == 1;
  }
  // File-access properties: parallel (MPI-IO) HDF5 on several ranks, POSIX on
  // one; the caller closes them.
  hid_t fileAccess() const {
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0 || (!alone() && H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL) < 0)) {
      if (fapl >= 0) H5Pclose(fapl);
      check(false, "cannot set up the file driver");
    }
    return fapl;
  }

  // Names of the links in group `path`, in name order.
  std::vector<std::string> children(const std::string& path) const {
    std::vector<std::string> names;
    H5G_info_t info;
    check(H5Gget_info_by_name(file, path.c_str(), &info, H5P_DEFAULT) >= 0, "cannot read group " + path);
    for (hsize_t i = 0; i < info.nlinks; ++i) {
      const ssize_t n = H5Lget_name_by_idx(file, path.c_str(), H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0,
                                           H5P_DEFAULT);
      check(n >= 0, "cannot list group " + path);
      std::string name(size_t(n) + 1, '\0');
      H5Lget_name_by_idx(file, path.c_str(), H5_INDEX_NAME, H5_ITER_INC, i, &name[0], name.size(),
                         H5P_DEFAULT);
      name.resize(size_t(n));
      names.push_back(name);
    }
    return names;
  }

  // The fields of a written step's group (name, components), for the index.
  void readShapes(const std::string& group, FieldShapes& shapes) const {
    if (H5Lexists(file, group.c_str(), H5P_DEFAULT) <= 0) return;
    for (const std::string& name : children(group)) {
      const std::string path = group + "/" + name;
      Handle dset(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
      check(dset >= 0, "cannot open dataset " + path);
      Handle space(H5Dget_space(dset), H5Sclose);
      hsize_t dims[2] = {0, 0};
      check(space >= 0 && H5Sget_simple_extent_ndims(space) == 2 &&
                H5Sget_simple_extent_dims(space, dims, nullptr) == 2,
            "not a 2-D dataset: " + path);
      shapes.emplace_back(name, int(dims[1]));
    }
  }

  // Appends to `err` where this rank's rows of integer dataset `path` differ
  // from `expected` (or the dataset's shape from [global, components]).
  void compareRows(const std::string& path, long long offset, long long owned, long long global,
                   int components, const std::vector<long long>& expected,
                   std::ostringstream& err) const {
    Handle dset(H5Lexists(file, path.c_str(), H5P_DEFAULT) > 0 ? H5Dopen2(file, path.c_str(), H5P_DEFAULT) : -1,
                H5Dclose);
    if (dset < 0) {
      err << "FieldWriter: " << h5Path << ": no " << path << "; ";
      return;
    }
    Handle space(H5Dget_space(dset), H5Sclose);
    hsize_t dims[2] = {0, 0};
    if (space < 0 || H5Sget_simple_extent_ndims(space) != 2 ||
        H5Sget_simple_extent_dims(space, dims, nullptr) != 2 || dims[0] != hsize_t(global) ||
        dims[1] != hsize_t(components)) {
      err << "FieldWriter: " << h5Path << ": " << path << " is " << dims[0] << " x " << dims[1]
          << ", this run has " << global << " x " << components << "; ";
      return;
    }
    if (owned == 0) return;
    const hsize_t start[2] = {hsize_t(offset), 0}, count[2] = {hsize_t(owned), hsize_t(components)};
    Handle mem(H5Screate_simple(2, count, nullptr), H5Sclose);
    std::vector<long long> rows(size_t(owned * components));
    if (mem < 0 || H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
        H5Dread(dset, H5T_NATIVE_LLONG, mem, space, H5P_DEFAULT, rows.data()) < 0)
      err << "FieldWriter: " << h5Path << ": cannot read " << path << "; ";
    else if (rows != expected)
      err << "FieldWriter: " << h5Path << ": " << path
          << " differs from this run's mesh (another mesh or rank count); ";
  }

  std::string xdmf() const;
  void writeXdmf() const;
  // Rank 0 rewrites the index; the outcome is shared so all ranks throw together.
  void publishXdmf() const {
    std::string error;
    if (rank == 0) {
      try {
        writeXdmf();
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    agree(comm, error);
  }
};

void FieldWriter::Impl::init(const std::string& dir, const FieldLayout& l) {
  comm = l.comm;
  nodeOffset = l.nodeOffset, nodesOwned = l.nodesOwned, nodesGlobal = l.nodesGlobal;
  elemOffset = l.elemOffset, elemsOwned = l.elemsOwned, elemsGlobal = l.elemsGlobal;
  faceOffset = l.faceOffset, facesOwned = l.facesOwned, facesGlobal = l.facesGlobal;
  directory = dir;
  h5Path = dir + "/fields.h5";
  MPI_Comm_rank(comm, &rank);

  // Each rank's rows must lie inside the global range and the owned counts
  // must add up to the global ones: otherwise rows of the file stay unwritten.
  std::ostringstream err;
  auto block = [&](const char* what, long long off, long long own, long long glob) {
    if (off < 0 || own < 0 || off + own > glob)
      err << "FieldWriter: " << what << " rows [" << off << ", " << off + own
          << ") outside [0, " << glob << ") on rank " << rank << "; ";
  };
  block("node", l.nodeOffset, l.nodesOwned, l.nodesGlobal);
  block("element", l.elemOffset, l.elemsOwned, l.elemsGlobal);
  block("face", l.faceOffset, l.facesOwned, l.facesGlobal);
  if (l.nodesGlobal <= 0 || l.elemsGlobal <= 0) err << "FieldWriter: empty mesh; ";
  if (l.hexConnectivity.size() != size_t(8 * std::max(l.elemsOwned, 0LL)) ||
      l.quadConnectivity.size() != size_t(4 * std::max(l.facesOwned, 0LL)))
    err << "FieldWriter: connectivity size does not match owned elements/faces; ";
  auto inRange = [&](long long n) { return n >= 0 && n < l.nodesGlobal; };
  if (!std::all_of(l.hexConnectivity.begin(), l.hexConnectivity.end(), inRange) ||
      !std::all_of(l.quadConnectivity.begin(), l.quadConnectivity.end(), inRange))
    err << "FieldWriter: connectivity refers to a node outside [0, nodesGlobal); ";
  long long owned[3] = {l.nodesOwned, l.elemsOwned, l.facesOwned}, sums[3];
  MPI_Allreduce(owned, sums, 3, MPI_LONG_LONG, MPI_SUM, comm);
  if (sums[0] != l.nodesGlobal || sums[1] != l.elemsGlobal || sums[2] != l.facesGlobal)
    err << "FieldWriter: owned rows do not add up to the global counts; ";
  agree(comm, err.str());

  // HDF5 would otherwise print its error stack to stderr; we throw instead.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

FieldWriter::FieldWriter(const std::string& directory, const FieldLayout& l) : impl_(new Impl) {
  Impl& m = *impl_;
  try {
    m.init(directory, l);
    Handle fapl(m.fileAccess(), H5Pclose);
    m.file = H5Fcreate(m.h5Path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    m.check(m.file >= 0, "cannot create file (does the directory exist?)");

    m.makeGroup("/mesh");
    m.makeGroup("/steps");
    m.writeRows("/mesh/hexahedra", H5T_NATIVE_LLONG, H5T_STD_I64LE, l.elemOffset, l.elemsOwned,
                l.elemsGlobal, 8, l.hexConnectivity.data());
    if (l.facesGlobal > 0)
      m.writeRows("/mesh/quads", H5T_NATIVE_LLONG, H5T_STD_I64LE, l.faceOffset, l.facesOwned,
                  l.facesGlobal, 4, l.quadConnectivity.data());
    m.check(H5Fflush(m.file, H5F_SCOPE_GLOBAL) >= 0, "cannot flush");
  } catch (...) {
    if (m.file >= 0) H5Fclose(m.file);
    delete impl_;
    throw;
  }
}

FieldWriter::FieldWriter(const std::string& directory, const FieldLayout& l, Append append)
    : impl_(new Impl) {
  Impl& m = *impl_;
  try {
    m.init(directory, l);
    Handle fapl(m.fileAccess(), H5Pclose);
    // Every rank learns whether the file opened, so none is left in a collective call.
    m.file = H5Fopen(m.h5Path.c_str(), H5F_ACC_RDWR, fapl);
    agree(m.comm, m.file >= 0 ? "" : "FieldWriter: " + m.h5Path + ": cannot open for appending");

    // The file must index nodes as this run does: each rank compares its rows.
    std::ostringstream err;
    m.compareRows("/mesh/hexahedra", l.elemOffset, l.elemsOwned, l.elemsGlobal, 8,
                  l.hexConnectivity, err);
    if (l.facesGlobal > 0)
      m.compareRows("/mesh/quads", l.faceOffset, l.facesOwned, l.facesGlobal, 4,
                    l.quadConnectivity, err);
    else if (H5Lexists(m.file, "/mesh/quads", H5P_DEFAULT) > 0)
      err << "FieldWriter: " << m.h5Path << " has contact faces, this run has none; ";
    agree(m.comm, err.str());

    // Steps up to lastKept are kept (and indexed again); later ones, written
    // after the checkpoint, are deleted (a collective call, same order on all ranks).
    for (const std::string& name : m.children("/steps")) {
      const std::string g = "/steps/" + name;
      int step = -1;
      std::from_chars(name.data(), name.data() + name.size(), step);
      if (step > append.lastKept || step < 0) {
        m.check(H5Ldelete(m.file, g.c_str(), H5P_DEFAULT) >= 0, "cannot delete " + g);
        continue;
      }
      StepRecord rec{g, 0.0, {}, {}, {}};
      {
        Handle attr(H5Aopen_by_name(m.file, g.c_str(), "time", H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
        m.check(attr >= 0 && H5Aread(attr, H5T_NATIVE_DOUBLE, &rec.time) >= 0,
                "cannot read the time of " + g);
      }
      m.readShapes(g + "/nodes", rec.nodal);
      m.readShapes(g + "/elements", rec.elements);
      if (m.facesGlobal > 0) m.readShapes(g + "/faces", rec.faces);
      m.steps.push_back(rec);
    }
    // The step a continuation follows on must be there (every rank sees the same file).
    char last[32];
    std::snprintf(last, sizeof last, "/steps/%06d", append.lastKept);
    if (m.steps.empty() || m.steps.back().group != last)
      throw std::runtime_error("FieldWriter: " + m.h5Path + " does not hold step " + std::to_string(append.lastKept));
    m.check(H5Fflush(m.file, H5F_SCOPE_GLOBAL) >= 0, "cannot flush");
    m.publishXdmf();
  } catch (...) {
    if (m.file >= 0) H5Fclose(m.file);
    delete impl_;
    throw;
  }
}

FieldWriter::~FieldWriter() {
  // H5Fclose is collective; it cannot throw, and its failure is not reportable here.
  if (impl_->file >= 0) H5Fclose(impl_->file);
  delete impl_;
}

void FieldWriter::writeStep(int step, double time, const std::vector<double>& coordinates,
                            const std::vector<Field>& nodal, const std::vector<Field>& elements,
                            const std::vector<Field>& faces) {
  Impl& m = *impl_;
  char group[32];
  std::snprintf(group, sizeof group, "/steps/%06d", step);
  StepRecord rec{group, time, {}, {}, {}};

  // Local checks, then one signature (step, time, field names and widths) that
  // all ranks must share, since the HDF5 metadata calls below must be identical.
  std::ostringstream err;
  const std::string where = std::string("FieldWriter: step ") + group + ": ";
  if (step < 0) err << where << "negative step number; ";
  for (const StepRecord& s : m.steps)
    if (s.group == rec.group) err << where << "already written; ";
  if (coordinates.size() != size_t(3 * m.nodesOwned))
    err << where << "coordinates need 3 values per owned node; ";
  if (m.facesGlobal == 0 && !faces.empty()) err << where << "face fields but no contact faces; ";
  auto collect = [&](const std::vector<Field>& fields, long long owned, FieldShapes& shapes) {
    for (const Field& f : fields) {
      if (!validName(f.name)) err << where << "bad field name '" << f.name << "'; ";
      if (f.components < 1) err << where << "field " << f.name << " has no components; ";
      else if (f.values.size() != size_t(f.components * owned))
        err << where << "field " << f.name << " needs " << f.components << " values per row; ";
      for (const auto& s : shapes)
        if (s.first == f.name) err << where << "duplicate field " << f.name << "; ";
      shapes.emplace_back(f.name, f.components);
    }
  };
  collect(nodal, m.nodesOwned, rec.nodal);
  collect(elements, m.elemsOwned, rec.elements);
  collect(faces, m.facesOwned, rec.faces);

  std::ostringstream sig;
  sig << step << ' ' << std::hexfloat << time;
  for (const FieldShapes* shapes : {&rec.nodal, &rec.elements, &rec.faces}) {
    sig << '|';
    for (const auto& s : *shapes) sig << s.first << ':' << s.second << ',';
  }
  std::string mine = sig.str(), root = mine;
  int length = int(root.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, m.comm);
  root.resize(size_t(length));
  MPI_Bcast(&root[0], length, MPI_CHAR, 0, m.comm);
  if (root != mine) err << where << "step, time or field list differs from rank 0; ";
  agree(m.comm, err.str());

  const std::string g = rec.group;
  m.makeGroup(g);
  {
    // The time attribute is a collective write too: every rank passes the same value.
    Handle gid(H5Gopen2(m.file, g.c_str(), H5P_DEFAULT), H5Gclose);
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle attr(gid >= 0 && space >= 0 ? H5Acreate2(gid, "time", H5T_IEEE_F64LE, space,
                                                    H5P_DEFAULT, H5P_DEFAULT)
                                       : -1,
                H5Aclose);
    m.check(attr >= 0 && H5Awrite(attr, H5T_NATIVE_DOUBLE, &time) >= 0,
            "cannot write time attribute of " + g);
  }
  m.writeDoubles(g + "/coordinates", m.nodeOffset, m.nodesOwned, m.nodesGlobal, 3, coordinates);
  m.makeGroup(g + "/nodes");
  for (const Field& f : nodal)
    m.writeDoubles(g + "/nodes/" + f.name, m.nodeOffset, m.nodesOwned, m.nodesGlobal,
                   f.components, f.values);
  m.makeGroup(g + "/elements");
  for (const Field& f : elements)
    m.writeDoubles(g + "/elements/" + f.name, m.elemOffset, m.elemsOwned, m.elemsGlobal,
                   f.components, f.values);
  if (m.facesGlobal > 0) {
    m.makeGroup(g + "/faces");
    for (const Field& f : faces)
      m.writeDoubles(g + "/faces/" + f.name, m.faceOffset, m.facesOwned, m.facesGlobal,
                     f.components, f.values);
  }
  m.check(H5Fflush(m.file, H5F_SCOPE_GLOBAL) >= 0, "cannot flush after step " + g);
  m.steps.push_back(rec);
  m.publishXdmf();
}

std::string FieldWriter::Impl::xdmf() const {
  std::ostringstream x;
  auto item = [&](long long rows, int cols, bool isInt, const std::string& path) {
    x << "<DataItem Dimensions=\"" << rows << ' ' << cols << "\" NumberType=\""
      << (isInt ? "Int" : "Float") << "\" Precision=\"8\" Format=\"HDF\">fields.h5:" << path
      << "</DataItem>\n";
  };
  auto attributes = [&](const FieldShapes& shapes, const char* center, const std::string& dir,
                        long long rows) {
    for (const auto& s : shapes) {
      x << "<Attribute Name=\"" << s.first << "\" AttributeType=\"" << attributeType(s.second)
        << "\" Center=\"" << center << "\">\n";
      item(rows, s.second, false, dir + s.first);
      x << "</Attribute>\n";
    }
  };
  auto geometry = [&](const std::string& g) {
    x << "<Geometry GeometryType=\"XYZ\">\n";
    item(nodesGlobal, 3, false, g + "/coordinates");
    x << "</Geometry>\n";
  };

  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n<Domain>\n"
    << "<Grid Name=\"capstan\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const StepRecord& s : steps) {
    // Without contact faces a step is the body grid alone, which any reader
    // handles; with them, a spatial collection of body and contact faces.
    const bool withFaces = facesGlobal > 0;
    if (withFaces)
      x << "<Grid Name=\"step_" << s.group.substr(7) << "\" GridType=\"Collection\" "
        << "CollectionType=\"Spatial\">\n"
        << "<Time Value=\"" << exact(s.time) << "\"/>\n";
    x << "<Grid Name=\"body\" GridType=\"Uniform\">\n";
    if (!withFaces) x << "<Time Value=\"" << exact(s.time) << "\"/>\n";
    x << "<Topology TopologyType=\"Hexahedron\" NumberOfElements=\"" << elemsGlobal << "\">\n";
    item(elemsGlobal, 8, true, "/mesh/hexahedra");
    x << "</Topology>\n";
    geometry(s.group);
    attributes(s.nodal, "Node", s.group + "/nodes/", nodesGlobal);
    attributes(s.elements, "Cell", s.group + "/elements/", elemsGlobal);
    x << "</Grid>\n";
    if (withFaces) {
      x << "<Grid Name=\"contact_faces\" GridType=\"Uniform\">\n"
        << "<Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"" << facesGlobal << "\">\n";
      item(facesGlobal, 4, true, "/mesh/quads");
      x << "</Topology>\n";
      geometry(s.group);
      attributes(s.faces, "Cell", s.group + "/faces/", facesGlobal);
      x << "</Grid>\n</Grid>\n";
    }
  }
  x << "</Grid>\n</Domain>\n</Xdmf>\n";
  return x.str();
}

void FieldWriter::Impl::writeXdmf() const {
  // Written under a temporary name and renamed, so a reader (or a run killed
  // mid-write) never sees a half-written index.
  const std::string path = directory + "/fields.xmf", tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << xdmf();
    out.close();
    if (!out) throw std::runtime_error("FieldWriter: " + tmp + ": cannot write");
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("FieldWriter: cannot rename " + tmp + " to " + path);
}

}  // namespace capstan
