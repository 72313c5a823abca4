# numpy access to the solver's state: the columns are views of the solver's memory, the
# (nodes, 3) arrays and the cell table have the documented shapes and agree with them.
import numpy as np

import papertear
from conftest import SMALL


def test_columns_are_views_that_change_when_stepping():
    sim = papertear.Simulation(overrides=SMALL, threads=2)
    x, vz = sim.x, sim.vz
    before = x.copy()
    assert np.shares_memory(x, sim.x)  # two reads see the same memory: no copy
    assert not x.flags.writeable and not x.flags.owndata
    sim.step(20)  # no split yet in 20 steps, so the columns were not reallocated
    assert sim.node_count == x.shape[0]
    assert not np.array_equal(x, before)  # the old view sees the solver's new values
    assert np.array_equal(x, sim.x) and np.array_equal(vz, sim.vz)


def test_positions_and_velocities_gather_the_columns():
    sim = papertear.Simulation(overrides=SMALL, threads=1)
    sim.step(30)
    p, v = sim.positions, sim.velocities
    assert p.shape == (sim.node_count, 3) and p.dtype == np.float32
    assert np.array_equal(p, np.stack([sim.x, sim.y, sim.z], axis=1))
    assert np.array_equal(v, np.stack([sim.vx, sim.vy, sim.vz], axis=1))
    assert np.abs(v).max() > 0


def test_positions_change_when_stepping():
    sim = papertear.Simulation(overrides=SMALL, threads=2)
    p0 = sim.positions
    sim.step(10)
    assert not np.array_equal(p0, sim.positions)


def test_cell_nodes_is_a_view_of_the_table():
    sim = papertear.Simulation(overrides=SMALL, threads=2)
    nx, ny, nl = sim.cells
    table = sim.cell_nodes
    assert table.shape == (nx * ny * nl, 8) and table.dtype == np.uint32
    assert np.shares_memory(table, sim.cell_nodes)
    assert table.max() < sim.node_count
    # Before any split, corner q of cell (i, j, k) is lattice vertex (i+dx, j+dy, k+dz).
    i, j, k = 3, 5, 1
    cell = i + nx * (j + ny * k)
    for q in range(8):
        dx, dy, dz = q & 1, (q >> 1) & 1, (q >> 2) & 1
        assert table[cell, q] == (i + dx) + (nx + 1) * ((j + dy) + (ny + 1) * (k + dz))


def test_splits_add_nodes_and_pieces():
    sim = papertear.Simulation(overrides=SMALL, threads=2)
    nodes = sim.node_count
    sim.step(300)
    summary = sim.summary()
    final = summary["final"]
    # Every split gives a node a copy, so a torn sheet has more nodes than it started with.
    assert final["splits_inplane"] + final["splits_interlayer"] > 0
    assert sim.node_count > nodes and sim.x.shape == (sim.node_count,)
    pieces = sim.pieces()
    assert pieces["count"] == final["pieces"] and sum(pieces["cells"]) == np.prod(sim.cells)
    assert summary["digest"] == sim.digest() and summary["steps"] == 300
    assert len(summary["frames"]) == 1 and summary["scene"]["sheet"]["cells"] == [30, 20, 3]
