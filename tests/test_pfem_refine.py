"""Node insertion and removal at a remeshing (refsph.pfem.refine, issue 24): mass, momentum and heat content
conserved to round-off; an inserted node carries its triangle's history; held nodes are never removed; nothing is
inserted where forbidden; bad rules are refused; and the quick PFEM cut with the rule on keeps every node's mass
positive and its total mass to 1e-12."""
import numpy as np
import pytest

from refsph.pfem import solid
from refsph.pfem.mesh import alpha_shape_mesh
from refsph.pfem.mesh import tributary_areas
from refsph.pfem.refine import NodeRule, refine_nodes, renumber_mesh

RHO, DX = 7800.0, 1e-4


def scene(seed=0):
    """A 7 x 7 lattice with one pair of nodes 0.2 spacings apart and one stretched corner (a large triangle), random
    velocities, temperatures and a history."""
    rng = np.random.default_rng(seed)
    X, Y = np.meshgrid(np.arange(7) * DX, np.arange(7) * DX)
    x = np.c_[X.ravel(), Y.ravel()]
    x[24] = x[25] + [-0.2 * DX, 0.0]                       # 24 next to 25: a close pair
    x[48] += [1.5 * DX, 1.5 * DX]                          # the top right corner pulled out: large triangles
    h = np.full(len(x), DX)
    mesh = alpha_shape_mesh(x, 3.0, h)
    m = RHO * tributary_areas(x, mesh.tri, len(x))
    nodes = solid.make_nodes(x, m, 300.0 + 50 * rng.random(len(x)))
    nodes.v[:] = rng.normal(size=nodes.v.shape)
    nodes.eps_p[:] = rng.random(len(x))
    k = len(mesh.tri)
    hist = solid.History(S=rng.normal(size=(k, 2, 2)) * 1e8, S_zz=rng.normal(size=k), eps_p=rng.random(k),
                         W_p=rng.random(k), J=1 + 0.01 * rng.random(k), eps_dot=rng.random(k))
    fixed = np.zeros((len(x), 2), bool)
    fixed[x[:, 1] == 0.0] = True
    return nodes, mesh, hist, h, fixed


def totals(nodes):
    return nodes.m.sum(), (nodes.m[:, None] * nodes.v).sum(axis=0), (nodes.m * nodes.T).sum()


def test_merge_and_insert_conserve_mass_momentum_and_heat():
    nodes, mesh, hist, h, fixed = scene()
    ids = np.arange(nodes.n)
    f_T = np.linspace(0.0, 1.0, nodes.n)
    out, h2, fixed2, extra, change = refine_nodes(nodes, mesh, hist, h, fixed, NodeRule(r_min=0.5, a_max=2.0),
                                                  extra=dict(id=(ids, "keep"), f_T=(f_T, "sum")))
    assert len(change.merged) == 1 and set(change.merged[0]) == {24, 25}
    assert len(change.parents) >= 1                                     # the stretched corner got a node
    assert out.n == nodes.n - 1 + len(change.parents)
    m0, P0, H0 = totals(nodes)
    m1, P1, H1 = totals(out)
    assert abs(m1 - m0) <= 1e-14 * m0 and np.all(out.m > 0)
    assert np.allclose(P1, P0, rtol=0, atol=1e-13 * np.abs(nodes.m[:, None] * nodes.v).sum())
    assert abs(H1 - H0) <= 1e-14 * H0
    assert abs(extra["f_T"].sum() - f_T.sum()) < 1e-14                  # the contact force summed, none made
    assert np.array_equal(np.sort(extra["id"][:nodes.n - 1]), np.delete(ids, change.merged[0, 1]))
    assert np.all(extra["id"][nodes.n - 1:] >= nodes.n)                 # new ids count on
    e = np.flatnonzero((np.sort(mesh.tri, axis=1) == np.sort(change.parents[0])).all(axis=1))[0]
    assert np.allclose(out.S[nodes.n - 1], hist.S[e]) and out.eps_p[nodes.n - 1] == hist.eps_p[e]
    assert np.allclose(out.x[nodes.n - 1], nodes.x[change.parents[0]].mean(axis=0))
    assert len(h2) == len(fixed2) == out.n and fixed2[:nodes.n - 1].sum() == fixed.sum()


def test_the_old_mesh_renumbered_keeps_its_surviving_triangles_history():
    nodes, mesh, hist, h, fixed = scene()
    out, *_, change = refine_nodes(nodes, mesh, hist, h, fixed, NodeRule(r_min=0.5, a_max=2.0))
    old, kept = renumber_mesh(mesh, hist, change)
    gone = (change.old_to_new[mesh.tri] < 0).any(axis=1)
    assert len(old.tri) == (~gone).sum() > 0 and old.tri.max() < out.n
    assert np.array_equal(kept.S, hist.S[~gone])
    new = alpha_shape_mesh(out.x, 3.0, np.full(out.n, DX))
    moved = solid.transfer_history(old, kept, new, out)
    same = (np.sort(new.tri, axis=1)[:, None, :] == np.sort(old.tri, axis=1)[None, :, :]).all(axis=2)
    i, j = np.nonzero(same)
    assert len(i) > 10 and np.array_equal(moved.S[i], kept.S[j])      # (a square lattice's diagonals flip)


def test_held_nodes_stay_and_forbidden_places_get_no_node():
    nodes, mesh, hist, h, fixed = scene()
    nodes.x[1] = nodes.x[0] + [0.1 * DX, 0.0]                           # two held nodes close: both stay
    mesh = alpha_shape_mesh(nodes.x, 3.0, h)
    hist = solid.history_from_nodes(nodes, mesh)
    out, *_, change = refine_nodes(nodes, mesh, hist, h, fixed, NodeRule(r_min=0.5, a_max=2.0),
                                   forbidden=lambda x: np.ones(len(x), bool))
    assert len(change.parents) == 0 and {0, 1}.isdisjoint(change.merged[:, 1])
    nodes.x[1] = nodes.x[8]                                             # a free node on a held one: the free goes
    nodes.x[8] += [0.1 * DX, 0.0]
    nodes.x[1] = nodes.x[0] + [0.3 * DX, 0.0]
    mesh = alpha_shape_mesh(nodes.x, 3.0, h)
    hist = solid.history_from_nodes(nodes, mesh)
    fixed[1] = False
    _, _, fixed2, _, change = refine_nodes(nodes, mesh, hist, h, fixed, NodeRule(r_min=0.5, a_max=50.0))
    assert [0, 1] in change.merged.tolist() and fixed2[0].all()


@pytest.mark.parametrize("r_min, a_max", [(0.0, 2.0), (1.0, 2.0), (0.5, 1.0), (np.nan, 2.0)])
def test_a_bad_rule_is_refused(r_min, a_max):
    with pytest.raises(ValueError, match="NodeRule"):
        NodeRule(r_min=r_min, a_max=a_max)


def test_a_tool_edge_poking_between_two_boundary_nodes_gets_a_node_on_its_surface():
    """The cut's ``edge_nodes``: a rounded tool whose edge pokes 0.3 spacings through the top boundary edge between
    two nodes, both outside it, gets one node on its surface inside that edge's triangle; mass, momentum and heat
    are conserved to round-off (each parent gives rho_k A lambda_k / 3)."""
    from refsph.penalty import RoundedPolygon
    from refsph.pfem.refine import barycentric, owner_triangles, tool_intrusions
    nodes, mesh, hist, h, fixed = scene()
    r = 0.4 * DX                                             # a square tool's lower corner, rounded by r, pokes down
    top = 6 * DX
    apex = np.array([2.5 * DX, top - 0.3 * DX + r])          # the arc's lowest point 0.3 DX below the top row
    core = np.array([[0.0, 0.0], [DX, DX], [0.0, 2 * DX], [-DX, DX]])
    tool = RoundedPolygon(core=core, radius=r)

    def gap(x):
        return tool.gap(x, apex)
    assert np.all(gap(nodes.x)[0] < 0)                       # no node inside the tool
    tri, lam = tool_intrusions(nodes.x, mesh, gap, 0.1 * h)
    assert len(tri) == 1 and np.all(lam > 0.05) and np.isclose(lam.sum(), 1.0)
    q = np.einsum("kp,kpd->kd", lam, nodes.x[mesh.tri[tri]])
    assert abs(gap(q)[0][0]) < 1e-3 * DX and abs(q[0, 0] - 2.5 * DX) < 0.02 * DX   # on the tool, under its edge
    edge = mesh.edges[owner_triangles(mesh.tri, mesh.edges) == tri[0]]
    assert np.allclose(nodes.x[edge.ravel(), 1], top)        # the poked edge is the top one, (2 DX, 3 DX)
    assert np.allclose(barycentric(nodes.x[mesh.tri[tri]], q), lam)
    out, h2, _, _, change = refine_nodes(nodes, mesh, hist, h, fixed, NodeRule(r_min=0.5, a_max=50.0),
                                         points=(tri, lam))
    assert len(change.parents) == 1 and out.n == nodes.n - len(change.merged) + 1 and np.allclose(out.x[-1], q[0])
    m0, P0, H0 = totals(nodes)
    m1, P1, H1 = totals(out)
    assert abs(m1 - m0) <= 1e-14 * m0 and np.all(out.m > 0)
    assert np.allclose(P1, P0, rtol=0, atol=1e-13 * np.abs(nodes.m[:, None] * nodes.v).sum())
    assert abs(H1 - H0) <= 1e-14 * H0
    assert out.eps_p[-1] == hist.eps_p[tri[0]] and h2[-1] == DX
    grazing = apex + [0.0, 0.25 * DX]                       # 0.05 DX through the edge: less than 0.1 h, nothing
    assert len(tool_intrusions(nodes.x, mesh, lambda x: tool.gap(x, grazing), 0.1 * h)[0]) == 0


def test_the_cut_with_edge_nodes_keeps_the_mesh_off_the_tool():
    """The quick cut's first 25 steps with ``edge_nodes``: nodes are put on the tool's edge, the total mass stays
    to 1e-12, and the tool's outline pokes through the boundary between two nodes far less than without (the
    overlap of benchmarks/pfem_edge_phase.py: 0.46 against 0.08 dx over the whole quick cut)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from pfem_edge_phase import overlap

    from refsph.pfem.cutting import CutRun, pfem_cut
    seen = {}
    for edge in (False, True):
        run = CutRun(pfem_cut(1, n_tu=5.0, travel=4.0, length=1.2e-3, edge_nodes=edge))
        m0, ov = run.nodes.m.sum(), []
        for _ in range(25):
            run.step()
            ov.append(overlap(run))
        assert abs(run.nodes.m.sum() - m0) <= 1e-12 * m0 and np.all(run.nodes.m > 0)
        seen[edge] = (float(np.mean(ov[10:])), run.inserted)
    assert seen[True][1] > seen[False][1]
    assert seen[True][0] < 0.5 * seen[False][0]
