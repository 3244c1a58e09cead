"""``mark_shared_edges`` through a k-d tree of edge bounding boxes: the same marks as testing all
pairs (the implementation before, kept below as the reference), on random panel sets (shared,
reversed, resampled, triple, near-miss at the tolerance, closed and zero-length edges) and on
real ones (a 60-face STEP file, the multichine dory's [[surfaces]]); and the number of candidate
pairs grows linearly with the panel count.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ght_cad.pattern import flat_pattern as fp
from ght_cad.pattern.flat_pattern import (MARK_FRACTIONS, BoundaryEdge, FlatPanel, _inside, _interp_polyline,
                                  _polyline_param, _sagitta3, mark_shared_edges)

ROOT = Path(__file__).resolve().parents[1]


def pairwise_mark_shared_edges(panels: Sequence[FlatPanel], rel_tol: float = 1e-5) -> int:
    """The implementation before the k-d tree (all pairs i < j), kept as the reference."""
    allpts = np.concatenate([e.xyz for p in panels for lp in p.loops for e in lp], axis=0)
    size = float(np.max(allpts.max(axis=0) - allpts.min(axis=0)))
    k = 0
    tick_all = 0.02 * max(float(np.max(hi - lo)) for lo, hi in (p.bbox() for p in panels))
    items = [(pi, e) for pi, p in enumerate(panels) for lp in p.loops for e in lp]
    sags = [_sagitta3(e.xyz) for _, e in items]
    used: set[int] = set()
    # cheap prefilter on the end points for all pairs (i, j > i) of one row at once (either
    # direction; closed edges must both be closed); the exact test below runs on the survivors only
    starts = np.array([e.xyz[0] for _, e in items]).reshape(-1, 3)
    ends = np.array([e.xyz[-1] for _, e in items]).reshape(-1, 3)
    gap = np.linalg.norm(starts - ends, axis=1)
    sag = np.asarray(sags, dtype=float)
    live = np.array([e.length_3d != 0 for _, e in items], dtype=bool)

    def dist(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return np.linalg.norm(q - p, axis=1)

    for i in range(len(items)):
        if not live[i]:
            continue
        js = np.arange(i + 1, len(items))
        tols = rel_tol * size + np.maximum(sag[i], sag[js])
        c1 = gap[i] <= tols
        ok = live[js] & (c1 == (gap[js] <= tols))
        fwd = np.maximum(dist(starts[i], starts[js]), dist(ends[i], ends[js]))
        bwd = np.maximum(dist(starts[i], ends[js]), dist(ends[i], starts[js]))
        ok &= c1 | (np.minimum(fwd, bwd) <= tols)
        for j in js[ok].tolist():
            (pi, e1), (pj, e2) = items[i], items[j]
            if i in used or j in used:
                continue
            tol = rel_tol * size + max(sags[i], sags[j])
            d12, _ = _polyline_param(e2.xyz, e1.xyz)
            if d12.max() > tol:
                continue
            d21, _ = _polyline_param(e1.xyz, e2.xyz)
            if d21.max() > tol:
                continue
            k += 1
            used.update((i, j))
            cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(e1.xyz, axis=0), axis=1))])
            frac_idx = np.interp(np.array(MARK_FRACTIONS) * cum[-1], cum, np.arange(len(cum)))
            p3, _ = _interp_polyline(e1.xyz, frac_idx)
            _, s2 = _polyline_param(e2.xyz, p3)
            for panel, edge, s in ((panels[pi], e1, frac_idx), (panels[pj], e2, s2)):
                loops = panel.loop_polylines()
                lo, hi = panel.bbox()
                tick = min(tick_all, 0.1 * float(np.min(hi - lo)))  # a narrow panel gets smaller marks
                pos, tan = _interp_polyline(edge.flat + panel.offset, s)
                nrm = np.stack([-tan[:, 1], tan[:, 0]], axis=1)
                probe = pos[2] + 2 * tick * nrm[2]
                if not _inside(probe[None], loops)[0]:
                    nrm = -nrm
                for q, nv in zip(pos, nrm):
                    panel.marks.append(np.array([q - tick * nv, q + tick * nv]))
                tp = pos[2] + 3 * tick * nrm[2]
                panel.texts.append((float(tp[0]), float(tp[1]), f"E{k}", 1.5 * tick))
    return k



def clone(panels: list[FlatPanel]) -> list[FlatPanel]:
    """Panels with copies of what mark_shared_edges reads and writes (no edge functions or maps)."""
    out = []
    for p in panels:
        loops = [[BoundaryEdge(e.name, None, None, e.length_3d, flat=e.flat.copy(), xyz=e.xyz.copy()) for e in lp]
                 for lp in p.loops]
        out.append(FlatPanel(p.label, loops, p.bend_lines.copy(), p.ruling_lengths_3d, p.ruling_lengths_flat, p.area_3d,
                             {}, offset=p.offset.copy(), marks=[m.copy() for m in p.marks], texts=list(p.texts)))
    return out


def assert_same(panels: list[FlatPanel], rel_tol: float = 1e-5) -> int:
    a, b = clone(panels), clone(panels)
    ka = mark_shared_edges(a, rel_tol)
    kb = pairwise_mark_shared_edges(b, rel_tol)
    assert ka == kb
    for pa, pb in zip(a, b):
        assert pa.texts == pb.texts
        assert len(pa.marks) == len(pb.marks)
        assert all(np.array_equal(x, y) for x, y in zip(pa.marks, pb.marks))
    return ka


def _edge(xyz: np.ndarray, name: str, offset: np.ndarray) -> BoundaryEdge:
    xyz = np.asarray(xyz, dtype=float)
    d = np.linalg.norm(np.diff(xyz, axis=0), axis=1).sum()
    return BoundaryEdge(name, None, None, float(d), flat=xyz[:, :2] + offset, xyz=xyz)


def random_panels(seed: int, nx: int = 6, ny: int = 5) -> tuple[list[FlatPanel], float]:
    """A jittered grid of curved quads sharing their edges (resampled, some reversed), plus
    duplicates (a third panel on an edge), near misses at the tolerance, closed and zero-length
    edges. Returns (panels, the model size)."""
    rng = np.random.default_rng(seed)
    gx = np.arange(nx + 1) * 10.0 + rng.uniform(-2, 2, (ny + 1, nx + 1))
    gy = (np.arange(ny + 1) * 10.0)[:, None] + rng.uniform(-2, 2, (ny + 1, nx + 1))

    def curve(p: np.ndarray, q: np.ndarray, m: int) -> np.ndarray:
        t = np.linspace(0, 1, m)[:, None]
        pts = (1 - t) * p + t * q
        bump = 0.5 * np.sin(np.pi * t[:, 0]) * np.sin(0.1 * (p[0] + q[0]) + 0.2 * (p[1] + q[1]))
        return np.column_stack([pts[:, 0], pts[:, 1], bump + 0.01 * (pts[:, 0] ** 2 + pts[:, 1] ** 2) / 100])

    panels = []
    for j in range(ny):
        for i in range(nx):
            c = [np.array([gx[j, i], gy[j, i]]), np.array([gx[j, i + 1], gy[j, i + 1]]),
                 np.array([gx[j + 1, i + 1], gy[j + 1, i + 1]]), np.array([gx[j + 1, i], gy[j + 1, i]])]
            off = np.array([0.0, 0.0])
            loop = []
            for k in range(4):
                p, q = c[k], c[(k + 1) % 4]
                m = int(rng.integers(5, 40))
                # the same 3-D curve whichever panel samples it: parametrize from the smaller end
                if (p[0], p[1]) <= (q[0], q[1]):
                    xyz = curve(p, q, m)
                else:
                    xyz = curve(q, p, m)[::-1]
                loop.append(_edge(xyz, f"e{k}", off))
            panels.append(FlatPanel(f"P{len(panels) + 1}", [loop], np.zeros((0, 2, 2)), np.zeros(0), np.zeros(0),
                                    1.0, {}))
    allpts = np.concatenate([e.xyz for p in panels for lp in p.loops for e in lp])
    size = float(np.max(allpts.max(0) - allpts.min(0)))
    extra = []
    for p in rng.choice(len(panels), 6, replace=False):  # duplicates and near misses of whole panels
        src = panels[p]
        for dz in (0.0, 1e-5 * size * (1 - 1e-3), 1e-5 * size * (1 + 1e-3), 1e-5 * size * 10):
            loop = []
            for e in src.loops[0][::-1]:
                xyz = e.xyz[::-1] + np.array([0, 0, dz])
                loop.append(_edge(xyz, e.name, np.array([0.0, 0.0])))
            extra.append(FlatPanel(f"D{len(extra)}", [loop], np.zeros((0, 2, 2)), np.zeros(0), np.zeros(0), 1.0, {}))
    # closed edges (circles, some shared, one resampled) and a zero-length edge
    for r, m, cx in ((3.0, 65, 5.0), (3.0, 65, 5.0), (3.0, 97, 5.0), (2.0, 33, 30.0), (2.5, 33, 30.0)):
        t = np.linspace(0, 2 * np.pi, m)
        circ = np.column_stack([cx + r * np.cos(t), 70 + r * np.sin(t), np.zeros(m)])
        pt = np.repeat(circ[:1], 2, axis=0)
        extra.append(FlatPanel(f"C{len(extra)}", [[_edge(circ, "c", np.zeros(2)), _edge(pt, "z", np.zeros(2))]],
                               np.zeros((0, 2, 2)), np.zeros(0), np.zeros(0), 1.0, {}))
    order = rng.permutation(len(panels) + len(extra))
    allp = panels + extra
    return [allp[k] for k in order], size


@pytest.mark.parametrize("seed", range(6))
def test_random_panels_same_marks_as_all_pairs(seed):
    panels, _ = random_panels(seed)
    k = assert_same(panels)
    assert k >= 49  # at least the grid's interior edges (6 x 5 cells: 49) are found
    assert assert_same(panels, rel_tol=1e-3) >= k
    assert_same(panels, rel_tol=0.0)


def test_candidates_grow_linearly():
    """Candidate pairs per edge stay bounded as the grid grows (all pairs: ~ n / 2 per edge)."""
    per_edge = []
    for nx in (5, 10, 20):
        panels, size = random_panels(1, nx, nx)
        items = [e for p in panels for lp in p.loops for e in lp]
        boxes = np.array([np.concatenate([e.xyz.min(0), e.xyz.max(0)]) for e in items])
        sag = np.array([_sagitta3(e.xyz) for e in items])
        cands = fp._shared_edge_candidates(boxes, 1e-5 * size + sag)
        per_edge.append(sum(len(c) for c in cands) / len(items))
    assert per_edge[-1] <= 2.0 and per_edge[-1] <= 1.5 * per_edge[0] + 0.5, per_edge


@pytest.mark.slow
def test_step_faces_same_marks_as_all_pairs(tmp_path, monkeypatch):
    import importlib.util

    from ght_cad.app.design import unroll_step

    spec = importlib.util.spec_from_file_location("bench_batch", ROOT / "bench" / "bench_batch.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    step = tmp_path / "many.step"
    bench.many_faces_step(step, 60)
    seen: list[int] = []
    real = fp.mark_shared_edges

    def check(panels, rel_tol=1e-5):
        seen.append(assert_same(panels, rel_tol))
        return real(panels, rel_tol)

    monkeypatch.setattr(fp, "mark_shared_edges", check)
    res = unroll_step(step)
    assert len(res.pattern.panels) >= 60 and seen and seen[0] > 0


@pytest.mark.slow
def test_dory_surfaces_same_marks_as_all_pairs(monkeypatch):
    from ght_cad.app.design import build_surfaces, load_design, unroll_surfaces

    seen: list[int] = []
    real = fp.mark_shared_edges

    def check(panels, rel_tol=1e-5):
        seen.append(assert_same(panels, rel_tol))
        return real(panels, rel_tol)

    monkeypatch.setattr(fp, "mark_shared_edges", check)
    design = load_design(ROOT / "examples" / "design_dory_multichine.toml")
    unroll_surfaces(build_surfaces(design))
    assert seen and seen[0] > 0
