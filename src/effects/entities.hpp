// What every effect does to set itself up: its entities' node ids, reference
// coordinates and dof ids in device views. Included by the effects' sources only.
#pragma once

#include <Kokkos_Core.hpp>

#include <string>
#include <vector>

#include "../mesh.hpp"
#include "effect.hpp"

namespace capstan {
namespace detail {

// Dof ids of entities given by their node ids.
template <class NodeView>
IntMatrix dofsOf(const NodeView& nodes) {
  const int nn = int(nodes.extent(1));
  IntMatrix dofs("dofs", nodes.extent(0), 3 * nn);
  Kokkos::parallel_for(
      "dofs", Kokkos::RangePolicy<ExecSpace>(0, nodes.extent(0)), KOKKOS_LAMBDA(int e) {
        for (int a = 0; a < nn; ++a)
          for (int i = 0; i < 3; ++i) dofs(e, 3 * a + i) = 3 * nodes(e, a) + i;
      });
  return dofs;
}

// Node ids and reference coordinates of entities (bricks: 8 nodes, faces: 4)
// from a flat node list, into device views.
template <class NodeView, class CoordView>
void loadEntities(const Mesh& mesh, const std::vector<int>& nodeList, const std::string& label,
                  NodeView& nodes, CoordView& X) {
  const size_t nn = NodeView::static_extent(1), count = nodeList.size() / nn;
  nodes = NodeView(label + " nodes", count);
  X = CoordView(label + " X", count);
  auto hn = Kokkos::create_mirror_view(nodes);
  auto hX = Kokkos::create_mirror_view(X);
  for (size_t e = 0; e < count; ++e)
    for (size_t a = 0; a < nn; ++a) {
      const int n = nodeList[nn * e + a];
      hn(e, a) = n;
      for (int i = 0; i < 3; ++i) hX(e, a, i) = mesh.X[3 * n + i];
    }
  Kokkos::deep_copy(nodes, hn);
  Kokkos::deep_copy(X, hX);
}

}  // namespace detail
}  // namespace capstan
