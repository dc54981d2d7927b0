// Parallel HDF5 field output with an XDMF index (opens in ParaView).
//
// Every rank owns a contiguous block of rows in the file: nodes
// [nodeOffset, nodeOffset + nodesOwned), elements [elemOffset, ...), contact
// faces [faceOffset, ...). Connectivity is given in file node indices, so the
// file never depends on the partition that wrote it beyond this row layout.
#pragma once

#include <mpi.h>

#include <string>
#include <vector>

namespace capstan {

struct FieldLayout {
  MPI_Comm comm = MPI_COMM_WORLD;
  long long nodeOffset = 0, nodesOwned = 0, nodesGlobal = 0;
  long long elemOffset = 0, elemsOwned = 0, elemsGlobal = 0;
  std::vector<long long> hexConnectivity;   // elemsOwned * 8, file node indices
  long long faceOffset = 0, facesOwned = 0, facesGlobal = 0;  // contact faces (quads)
  std::vector<long long> quadConnectivity;  // facesOwned * 4, file node indices
};

// One field: `components` values per row (node, element or face), rows in the
// order of the layout's owned rows. components: 1 scalar, 3 vector, 6 symmetric
// tensor (xx, yy, zz, xy, yz, xz).
struct Field {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

class FieldWriter {
 public:
  // Creates (truncates) DIR/fields.h5 and writes the mesh topology once.
  // Collective over layout.comm. Throws std::runtime_error on I/O failure.
  FieldWriter(const std::string& directory, const FieldLayout& layout);
  // Restart: opens DIR/fields.h5 written by an earlier run with the same layout
  // (its connectivity must equal this layout's, row for row), deletes the steps
  // numbered above `lastKept` (written after the checkpoint the run continues
  // from) and appends after the rest; DIR/fields.xmf is rewritten for them.
  struct Append {
    int lastKept;
  };
  FieldWriter(const std::string& directory, const FieldLayout& layout, Append append);
  ~FieldWriter();
  FieldWriter(const FieldWriter&) = delete;
  FieldWriter& operator=(const FieldWriter&) = delete;

  // Appends one step (collective): `coordinates` (3 per owned node) is its geometry; nodal and
  // element fields on the body grid, face fields on the faces' (facesGlobal > 0). Then fields.h5 is
  // flushed and fields.xmf rewritten atomically: a run killed later leaves readable files.
  void writeStep(int step, double time, const std::vector<double>& coordinates,
                 const std::vector<Field>& nodal, const std::vector<Field>& elements,
                 const std::vector<Field>& faces);

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace capstan
