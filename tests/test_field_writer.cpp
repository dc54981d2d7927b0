// FieldWriter: writes a 2-hex mesh (12 nodes) with one contact quad on however
// many ranks the test runs, then reads fields.h5 back serially on rank 0.
#include "field_writer.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}
int size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

// A fresh directory per test, made by rank 0 and shared by name.
std::string makeTempDir() {
  char name[64] = "/tmp/capstan_fw_XXXXXX";
  if (rank() == 0 && mkdtemp(name) == nullptr) name[0] = '\0';
  MPI_Bcast(name, sizeof name, MPI_CHAR, 0, MPI_COMM_WORLD);
  if (name[0] == '\0') throw std::runtime_error("mkdtemp failed");
  return name;
}

void removeDir(const std::string& dir) {
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) std::filesystem::remove_all(dir);
}

// Rank r of n owns rows [r*N/n, (r+1)*N/n): contiguous, some ranks maybe empty.
void split(long long global, long long& offset, long long& owned) {
  offset = global * rank() / size();
  owned = global * (rank() + 1) / size() - offset;
}

// Node (i, j, k) on a 3x2x2 grid has file index i + 3*(j + 2*k).
long long node(int i, int j, int k) { return i + 3 * (j + 2 * k); }
std::vector<long long> hex(int e) {
  return {node(e, 0, 0), node(e + 1, 0, 0), node(e + 1, 1, 0), node(e, 1, 0),
          node(e, 0, 1), node(e + 1, 0, 1), node(e + 1, 1, 1), node(e, 1, 1)};
}
const std::vector<long long> kQuad = {node(0, 0, 1), node(1, 0, 1), node(1, 1, 1), node(0, 1, 1)};

// Deterministic value of (step, field, global row, component).
double value(int step, int field, long long row, int comp) {
  return step * 1000.0 + field * 100.0 + row * 10.0 + comp + 0.25;
}
double coordinate(int step, long long n, int c) {
  const long long ijk[3] = {n % 3, (n / 3) % 2, n / 6};
  return double(ijk[c]) + 0.125 * step;
}

capstan::FieldLayout layout(bool withFaces) {
  capstan::FieldLayout l;
  l.nodesGlobal = 12;
  split(l.nodesGlobal, l.nodeOffset, l.nodesOwned);
  l.elemsGlobal = 2;
  split(l.elemsGlobal, l.elemOffset, l.elemsOwned);
  for (long long e = l.elemOffset; e < l.elemOffset + l.elemsOwned; ++e)
    for (long long n : hex(int(e))) l.hexConnectivity.push_back(n);
  if (withFaces) {
    l.facesGlobal = 1;
    split(l.facesGlobal, l.faceOffset, l.facesOwned);
    if (l.facesOwned == 1) l.quadConnectivity = kQuad;
  }
  return l;
}

capstan::Field field(const std::string& name, int id, int comps, int step, long long offset,
                     long long owned) {
  capstan::Field f{name, comps, {}};
  for (long long r = offset; r < offset + owned; ++r)
    for (int c = 0; c < comps; ++c) f.values.push_back(value(step, id, r, c));
  return f;
}

void writeSteps(const std::string& dir, bool withFaces) {
  const capstan::FieldLayout l = layout(withFaces);
  capstan::FieldWriter writer(dir, l);
  for (int step : {0, 7}) {
    std::vector<double> coords;
    for (long long n = l.nodeOffset; n < l.nodeOffset + l.nodesOwned; ++n)
      for (int c = 0; c < 3; ++c) coords.push_back(coordinate(step, n, c));
    std::vector<capstan::Field> faces;
    if (withFaces) faces = {field("pressure", 4, 1, step, l.faceOffset, l.facesOwned)};
    writer.writeStep(step, 0.5 * step, coords,
                     {field("displacement", 0, 3, step, l.nodeOffset, l.nodesOwned),
                      field("temperature", 1, 1, step, l.nodeOffset, l.nodesOwned)},
                     {field("stress", 2, 6, step, l.elemOffset, l.elemsOwned),
                      field("F", 3, 9, step, l.elemOffset, l.elemsOwned)},
                     faces);
  }
}

// Reads a whole 2-D dataset; `dims` receives its shape.
template <typename T>
std::vector<T> readAll(hid_t file, const std::string& path, hid_t type, hsize_t dims[2]) {
  hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << path;
  if (d < 0) return {};
  hid_t s = H5Dget_space(d);
  EXPECT_EQ(H5Sget_simple_extent_ndims(s), 2) << path;
  H5Sget_simple_extent_dims(s, dims, nullptr);
  std::vector<T> out(dims[0] * dims[1]);
  EXPECT_GE(H5Dread(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << path;
  H5Sclose(s);
  H5Dclose(d);
  return out;
}

void expectField(hid_t file, const std::string& path, int id, int step, long long rows, int comps) {
  hsize_t dims[2] = {0, 0};
  const std::vector<double> v = readAll<double>(file, path, H5T_NATIVE_DOUBLE, dims);
  ASSERT_EQ(dims[0], hsize_t(rows)) << path;
  ASSERT_EQ(dims[1], hsize_t(comps)) << path;
  for (long long r = 0; r < rows; ++r)
    for (int c = 0; c < comps; ++c)
      EXPECT_EQ(v[r * comps + c], value(step, id, r, c)) << path << " row " << r << " comp " << c;
}

// Serial read-back on rank 0, after the writer has closed the file.
void checkFile(const std::string& dir, bool withFaces) {
  hid_t file = H5Fopen((dir + "/fields.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  hsize_t dims[2] = {0, 0};
  const std::vector<long long> hexes =
      readAll<long long>(file, "/mesh/hexahedra", H5T_NATIVE_LLONG, dims);
  EXPECT_EQ(dims[0], 2u);
  EXPECT_EQ(dims[1], 8u);
  std::vector<long long> expected = hex(0), second = hex(1);
  expected.insert(expected.end(), second.begin(), second.end());
  EXPECT_EQ(hexes, expected);
  EXPECT_EQ(H5Lexists(file, "/mesh/quads", H5P_DEFAULT) > 0, withFaces);
  if (withFaces) {
    EXPECT_EQ(readAll<long long>(file, "/mesh/quads", H5T_NATIVE_LLONG, dims), kQuad);
    EXPECT_EQ(dims[0], 1u);
    EXPECT_EQ(dims[1], 4u);
  }
  for (int step : {0, 7}) {
    char g[32];
    std::snprintf(g, sizeof g, "/steps/%06d", step);
    const std::string group = g;
    double time = -1;
    hid_t a = H5Aopen_by_name(file, g, "time", H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(a, 0);
    EXPECT_GE(H5Aread(a, H5T_NATIVE_DOUBLE, &time), 0);
    H5Aclose(a);
    EXPECT_EQ(time, 0.5 * step);

    const std::vector<double> xyz =
        readAll<double>(file, group + "/coordinates", H5T_NATIVE_DOUBLE, dims);
    EXPECT_EQ(dims[0], 12u);
    EXPECT_EQ(dims[1], 3u);
    for (long long n = 0; n < 12 && xyz.size() == 36; ++n)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(xyz[n * 3 + c], coordinate(step, n, c));
    expectField(file, group + "/nodes/displacement", 0, step, 12, 3);
    expectField(file, group + "/nodes/temperature", 1, step, 12, 1);
    expectField(file, group + "/elements/stress", 2, step, 2, 6);
    expectField(file, group + "/elements/F", 3, step, 2, 9);
    if (withFaces) expectField(file, group + "/faces/pressure", 4, step, 1, 1);
  }
  H5Fclose(file);

  std::ifstream in(dir + "/fields.xmf");
  ASSERT_TRUE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const std::string xmf = text.str();
  for (const char* s : {"CollectionType=\"Temporal\"", "Hexahedron", "fields.h5:/steps/000000/",
                        "fields.h5:/steps/000007/", "<Time Value=\"3.5\"/>", "Tensor6", "Matrix",
                        "AttributeType=\"Vector\" Center=\"Node\"", "Center=\"Cell\""})
    EXPECT_NE(xmf.find(s), std::string::npos) << s;
  EXPECT_EQ(xmf.find("Quadrilateral") != std::string::npos, withFaces);
  EXPECT_EQ(xmf.find("contact_faces") != std::string::npos, withFaces);
  EXPECT_EQ(xmf.find("CollectionType=\"Spatial\"") != std::string::npos, withFaces);
  EXPECT_FALSE(std::filesystem::exists(dir + "/fields.xmf.tmp"));
}

void runCase(bool withFaces) {
  const std::string dir = makeTempDir();
  writeSteps(dir, withFaces);
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);  // writer left no open handle
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) checkFile(dir, withFaces);
  removeDir(dir);
}

TEST(FieldWriter, MeshWithContactFaces) { runCase(true); }

TEST(FieldWriter, MeshWithoutContactFaces) { runCase(false); }

// A bad argument on one rank makes every rank throw, so none hangs in HDF5.
TEST(FieldWriter, BadArgumentThrowsOnAllRanks) {
  const std::string dir = makeTempDir();
  {
    const capstan::FieldLayout l = layout(true);
    capstan::FieldWriter writer(dir, l);
    std::vector<double> coords(size_t(3 * l.nodesOwned), 0.0);
    if (rank() == size() - 1) coords.push_back(1.0);
    EXPECT_THROW(writer.writeStep(0, 0.0, coords, {}, {}, {}), std::runtime_error);
    coords.resize(size_t(3 * l.nodesOwned));
    EXPECT_THROW(writer.writeStep(1, 0.0, coords, {{"bad name", 1, {}}}, {}, {}),
                 std::runtime_error);
    EXPECT_NO_THROW(writer.writeStep(1, 0.0, coords, {}, {}, {}));
    EXPECT_THROW(writer.writeStep(1, 0.0, coords, {}, {}, {}), std::runtime_error);  // repeated
  }
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
  removeDir(dir);
}

// Restart: steps 0 and 7 written, then 8 (as if written after a checkpoint of
// step 7 and then killed); appending after 7 drops 8, keeps 0 and 7 and their
// index, and the next steps follow. A file of another mesh is refused.
TEST(FieldWriter, AppendAfterCheckpoint) {
  const std::string dir = makeTempDir();
  writeSteps(dir, true);
  const capstan::FieldLayout l = layout(true);
  auto coords = [&](int step) {
    std::vector<double> c;
    for (long long n = l.nodeOffset; n < l.nodeOffset + l.nodesOwned; ++n)
      for (int k = 0; k < 3; ++k) c.push_back(coordinate(step, n, k));
    return c;
  };
  auto nodal = [&](int step) {
    return std::vector<capstan::Field>{field("displacement", 0, 3, step, l.nodeOffset, l.nodesOwned)};
  };
  {
    capstan::FieldWriter writer(dir, l, capstan::FieldWriter::Append{7});
    writer.writeStep(8, 4.0, coords(99), nodal(99), {}, {});  // the step a restart redoes
  }
  {
    capstan::FieldWriter writer(dir, l, capstan::FieldWriter::Append{7});
    writer.writeStep(8, 4.0, coords(8), nodal(8), {}, {});
    writer.writeStep(9, 4.5, coords(9), nodal(9), {}, {});
  }
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) {
    checkFile(dir, true);  // steps 0 and 7 as first written
    hid_t file = H5Fopen((dir + "/fields.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    hsize_t n = 0;
    hid_t steps = H5Gopen2(file, "/steps", H5P_DEFAULT);
    H5G_info_t info;
    H5Gget_info(steps, &info);
    n = info.nlinks;
    H5Gclose(steps);
    EXPECT_EQ(n, 4u);  // 0, 7, 8, 9: the first step 8 is gone
    for (int step : {8, 9}) {
      char g[40];
      std::snprintf(g, sizeof g, "/steps/%06d/nodes/displacement", step);
      expectField(file, g, 0, step, 12, 3);
    }
    H5Fclose(file);
    std::ifstream in(dir + "/fields.xmf");
    std::stringstream xmf;
    xmf << in.rdbuf();
    const std::string text = xmf.str();
    size_t grids = 0;
    for (size_t p = text.find("<Time "); p != std::string::npos; p = text.find("<Time ", p + 1)) ++grids;
    EXPECT_EQ(grids, 4u);
    EXPECT_NE(text.find("/steps/000007/elements/stress"), std::string::npos);  // kept step's fields indexed
    EXPECT_NE(text.find("<Time Value=\"4.5\"/>"), std::string::npos);
  }
  // Another mesh (no contact faces): refused on every rank, file untouched.
  EXPECT_THROW(capstan::FieldWriter(dir, layout(false), capstan::FieldWriter::Append{7}), std::runtime_error);
  EXPECT_EQ(H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL), 0);
  removeDir(dir);
}

TEST(FieldWriter, MissingDirectoryThrows) {
  EXPECT_THROW(capstan::FieldWriter("/nonexistent/capstan_fw", layout(true)), std::runtime_error);
}

// On ranks other than 0, print only failed assertions, tagged with the rank.
class RankFailurePrinter : public ::testing::EmptyTestEventListener {
  void OnTestPartResult(const ::testing::TestPartResult& r) override {
    if (r.failed())
      std::fprintf(stderr, "[rank %d] %s:%d: %s\n", rank(), r.file_name() ? r.file_name() : "?",
                   r.line_number(), r.summary());
  }
};

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  // Rank 0 prints the usual report; a failure on any rank fails every rank's exit code.
  if (rank() != 0) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailurePrinter);
  }
  int failed = RUN_ALL_TESTS() != 0 ? 1 : 0, anyFailed = 0;
  MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return anyFailed;
}
