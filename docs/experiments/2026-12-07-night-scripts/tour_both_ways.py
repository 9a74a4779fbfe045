"""How many corridor edges CYCLIC's one tour walks in both directions, per map."""
from patrolsb3.core.maps import load_map
from patrolsb3.strategies.cyclic import build_tour
from patrolsb3.strategies.navigation import patrol_distances

for m in "ABCD":
    spec = load_map(m)
    cells = spec.vertex_cells[build_tour(spec)]
    dist, fi = patrol_distances(spec), spec.free_index
    path = [int(cells[0])]
    for nxt in list(cells[1:]) + [cells[0]]:
        cur = path[-1]
        while cur != nxt:   # one shortest station-avoiding step at a time
            cur = next(int(c) for c, ok in zip(spec.neighbour[cur, :4], spec.move_ok[cur, :4])
                       if ok and fi[c] >= 0 and dist[fi[c], fi[nxt]] == dist[fi[cur], fi[nxt]] - 1)
            path.append(cur)
    edges = set(zip(path[:-1], path[1:]))
    both = sum(1 for a, b in edges if (b, a) in edges) // 2
    print(m, "tour steps", len(path) - 1, "vertices", spec.n_vertices,
          "edges walked both ways", both, "of", len({tuple(sorted(e)) for e in edges}))
