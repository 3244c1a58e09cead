r"""Markdown report of :func:`ght_cad.app.design.run_design` (``report.md``).
"""

from __future__ import annotations

from typing import Any


def _f(x: Any, fmt: str = ".6g", none: str = "n/a") -> str:
    """``x`` formatted, ``none`` for a value the report leaves out (``null`` in report.json)."""
    return none if x is None else format(x, fmt)


def report_markdown(r: dict[str, Any]) -> str:
    """Markdown report of :func:`run_design` (tables of the measured numbers, figure links)."""
    L = [f"# {r['name']}: ght_cad report", ""]
    L.append(f"Design: `{r['source']}` · units: {r['units']} · ght_cad {r['versions']['ght_cad']} · "
             f"computed in {r['elapsed_s']:.1f} s")
    L.append("")
    L.append(f"GHT definition: {r['ght_definition']}.")
    L.append("")
    if r.get("curves"):
        L += ["## Curves", "", "| name | degree | dim | μ | ν | γ | arc length | max curvature |", "|---|---|---|---|---|---|---|---|"]
        for c in r["curves"]:
            L.append(f"| {c['name']} | {c['degree']} | {c['dim']} | {c['mu']:.4g} | {c['nu']:.4g} | {c['gamma']:.4g} | "
                     f"{c['arc_length']:.6g} | {_f(c['curvature_max'], '.4g')} |")
        L.append("")
    if r.get("joins"):
        L += ["### Joins (measured independently of the construction)", "",
              "| first → second | requested | achieved C | achieved G | satisfied |", "|---|---|---|---|---|"]
        for j in r["joins"]:
            L.append(f"| {j['first']} → {j['second']} | {j['requested']} | C{j['achieved_C']} | G{j['achieved_G']} | "
                     f"{'yes' if j['satisfied'] else 'NO'} |")
        L.append("")
    if r.get("surface"):
        L += _surface_section(r["surface"], r, "Surface", r.get("developability_initial"), r.get("developability"))
        if r.get("initial_surface_error"):
            L += [f"The file's shape parameters give no surface ({r['initial_surface_error']}); the values above "
                  "are those of the optimized parameters.", ""]
        L += _strips_section(r["surface"])
    for x in r.get("surfaces") or []:
        L += _surface_section(x["surface"], r, f"Surface `{x['name']}`", None, x["developability"])
        L += _strips_section(x["surface"])
    if r.get("optimization"):
        o = r["optimization"]
        L += ["## Shape-parameter optimization", "",
              f"{o['method']} on {o['objective']}: {_f(o['initial_value'], '.8g')} → {o['best_value']:.8g} in "
              f"{o['iterations']} iterations ({o['nfev']} evaluations, {o['time_s']:.2f} s); best "
              + ", ".join(f"{k} = {v:.6g}" for k, v in o["best_parameters"].items()), ""]
        if o.get("sheet"):
            L += _sheet_rule_lines(o["sheet"], r["units"])
        if o.get("strips"):
            L += [f"Per strip ({o['objective']} of its dual curve as built):", "",
                  "| strip | before | after | μ, ν, γ before | μ, ν, γ after |", "|---|---|---|---|---|"]
            for x in o["strips"]:
                L.append(f"| {x['name']} | {_f(x['initial_value'], '.8g')} | {x['best_value']:.8g} | "
                         + ", ".join(f"{v:.4g}" for v in x["initial_parameters"].values()) + " | "
                         + ", ".join(f"{v:.4g}" for v in x["best_parameters"].values()) + " |")
            L.append("")
        if o.get("joints"):
            L += ["Joints after optimization:", "", "| first → second | requested | measured | satisfied |",
                  "|---|---|---|---|"]
            for j in o["joints"]:
                L.append(f"| {j['first']} → {j['second']} | {j['requested']} | G{j['achieved_G']} | "
                         f"{'yes' if j['satisfied'] else 'NO'} |")
            L.append("")
    if (r.get("brep") or {}).get("skipped"):
        L += ["## B-rep", "", f"Not built: {r['brep']['skipped']}.", ""]
    elif r.get("brep"):
        b = r["brep"]
        L += ["## B-rep", "", f"{b['faces']} face(s){' in one shell' if b.get('shape') == 'shell' else ''} "
              f"(valid: {b['valid']}), area {b['area']:.9g} {r['units']}², "
              f"{b['curve_edges']} curve edge(s).", ""]
    if r.get("flat_pattern"):
        p = r["flat_pattern"]
        L += ["## Flat pattern (spec section 6)", "", f"Area {p['area']:.9g} {r['units']}², {p['bend_lines']} bend lines, "
              f"{len(p.get('panels') or [1])} panel(s)" + (f", edge marks {', '.join(p['edge_marks'])}" if p.get("edge_marks") else "")
              + ".", "",
              "| quantity | max | rms |", "|---|---|---|"]
        for k, v in p["report"].items():
            L.append(f"| {k} | {v['max']:.3e} | {v['rms']:.3e} |")
        L.append("")
        for sh in p.get("sheet") or []:
            L += [f"### Sheet {sh['panel']}: T = {sh['thickness']:.6g} {r['units']}, K = {sh['k_factor']:.4g}, "
                  f"side {sh['side']}", "", "| edge | inside | neutral (cut) | outside |", "|---|---|---|---|"]
            L += [f"| {e['edge']} | {e['inside']:.9g} | {e['neutral']:.9g} | {e['outside']:.9g} |" for e in sh["edges"]]
            L += ["", "| bend | u | R at a | R at b | angle (deg) | at |", "|---|---|---|---|---|---|"]
            L += [f"| {'all' if f['line'] == 0 else f['line']} | {f['u']:.6f} | {_f(f['radius_a'], '.9g', '∞ (straight)')} | "
                  f"{_f(f['radius_b'], '.9g', '∞ (straight)')} | "
                  f"{f['angle_deg']:.6f} | {f['position']:.6g} |" for f in sh["forming"]]
            L.append("")
    if (r.get("plate") or {}).get("surfaces"):
        L += _plates_section(r["plate"], r["units"])
    L += ["## Files", ""]
    for f in r.get("files", []):
        L.append(f"- [{f}]({f})" + (f"\n\n  ![{f}]({f})" if f.endswith(".png") else ""))
    L.append("")
    return "\n".join(L)


def _sheet_rule_lines(sh: dict[str, Any], units: str) -> list[str]:
    """The optimization's sheet rule in words: candidates refused, the start, the result's radius."""
    by = ", ".join(f"{n} {k}" for k, n in sh["refused_by"].items() if n)
    start = ("passes the sheet check" + (f" (smallest bending radius {_f(sh['initial_min_bending_radius'])} {units})"
                                          if sh.get("initial_min_bending_radius") is not None else "")
             if sh["initial_feasible"] else
             f"is refused by the sheet check ({sh['initial_error']})" if sh["initial_feasible"] is False else
             "gives no surface")
    return [f"Sheet constraint (T = {sh['thickness']:.6g} {units}, K = {sh['k_factor']:.4g}, side {sh['side']}, "
            f"|K·T| = {sh['k_t']:.6g} {units}): every candidate surface was checked against the sheet "
            f"(margin {sh['margin']:g}); {sh['candidates_refused']} of {sh['candidates_checked']} refused"
            + (f" ({by})" if by else "") + f", so the constraint was {'active' if sh['active'] else 'not active'}. "
            f"The start design {start}. Smallest bending radius of the result: {_f(sh['min_bending_radius'])} {units} "
            f"(= {_f(sh['min_radius_over_k_t'], '.6g')} × |K·T|); it would carry a sheet up to "
            f"{_f(sh['thickness_factor'], '.6g')} × T" + (f", beyond that {_RULES.get(sh['limiting_rule'], sh['limiting_rule'])}"
                                                       if sh.get("limiting_rule") else "") + ".", ""]


_RULES = {"radius": "the neutral offset |K·T| would reach a bending radius",
          "centre": "the material would reach a centre of curvature"}


def _surface_section(s: dict[str, Any], r: dict[str, Any], title: str, initial: dict[str, Any] | None,
                     final: dict[str, Any] | None) -> list[str]:
    """Type, shape parameters, area, ruling lengths and the developability table of one surface;
    for a ``rails`` loft also its segments, fan share and edge of regression."""
    shape = ", ".join(f"{k} = {v:.6g}" for k, v in s["shape_parameters"].items())
    L = [f"## {title}", "", f"Type: `{s['type']}`" + (f" · shape parameters: {shape}" if shape else "")
         + f" · area {s['area_3d']:.9g} {r['units']}² · ruling length {s['ruling_length_min']:.6g}–"
         f"{s['ruling_length_max']:.6g} {r['units']}", ""]
    L += ["### Developability degree (spec section 5)", "", "| | θ_max [deg] | θ_rms [deg] | DD | R |", "|---|---|---|---|---|"]
    for label, d in (("initial", initial), ("final", final)):
        if d:
            L.append(f"| {label} | {_f(d['theta_max'], '.3e')} | {_f(d['theta_rms'], '.3e')} | {_f(d['dd'], '.12f')} | "
                     f"{_f(d['R'], '.3e')} |")
    L.append("")
    lf = s.get("loft")
    if lf:
        L += [f"### Developable loft between `{lf['curve_a']}` and `{lf['curve_b']}` (spec section 5.7)", "",
              f"Fan share {lf['fan_share']:.6g} (fan area {lf['fan_area']:.6g} of {lf['area']:.9g} {r['units']}²) · "
              f"θ_max {lf['theta_max_deg']:.3e}° over the sampled rulings · |F| residual {lf['f_residual_max']:.2e} · "
              f"ruling-field fairness ∫|d'|² {lf['fairness']:.6g} · {len(lf['degenerate_rulings'])} degenerate ruling(s) · "
              "edge of regression " + (f"between the rails at {len(lf['regression'])} sampled ruling(s)" if lf["regression"]
                                       else f"clear of the rails (margin {_f(lf['regression_clearance'], '.3g')})")
              + (" · rail b traced reversed" if lf["reversed_b"] else ""), "",
              "| segment | t on rail a | s on rail b | area |", "|---|---|---|---|"]
        for g in lf["segments"]:
            L.append(f"| {g['kind']} | {g['t'][0]:.6g}–{g['t'][1]:.6g} | {g['s'][0]:.6g}–{g['s'][1]:.6g} | {g['area']:.9g} |")
        L.append("")
    return L


def _strips_section(s: dict[str, Any]) -> list[str]:
    """The strips and joints tables of a composite surface, the panel table of an approximation
    (:func:`ght_cad.app.design.approximate.report_markdown`); nothing for other types."""
    L: list[str] = []
    if s.get("approximation"):
        from .approximate import report_markdown as approximation_markdown

        L += approximation_markdown(s["approximation"], heading="###").splitlines() + [""]
    if s.get("strips"):
        L += ["### Strips", "", "| strip | μ | ν | γ | area | θ_max [deg] | DD |", "|---|---|---|---|---|---|---|"]
        for x in s["strips"]:
            sp, d = x["shape_parameters"], x["developability"]
            L.append(f"| {x['name']} | {sp['mu']:.4g} | {sp['nu']:.4g} | {sp['gamma']:.4g} | {x['area_3d']:.9g} | "
                     f"{d['theta_max']:.3e} | {d['dd']:.12f} |")
        L.append("")
    if s.get("joints"):
        L += ["### Joints between strips (measured independently of the construction)", "",
              "| first → second | requested | achieved | satisfied | plane angle [deg] | residuals |",
              "|---|---|---|---|---|---|"]
        for j in s["joints"]:
            L.append(f"| {j['first']} → {j['second']} | {j['requested']} | G{j['achieved_G']} | "
                     f"{'yes' if j['satisfied'] else 'NO'} | {j['plane_angle_deg']:.2e} | "
                     + ", ".join(f"{x:.1e}" for x in j["residuals"]) + " |")
        L.append("")
    return L


def _plates_section(pl: dict[str, Any], units: str) -> list[str]:
    """The plates of a ``[[surfaces]]`` design with a ``[sheet]``: per surface its sheet, the side
    its material goes and the volume against the closed form; per shared rail the joint."""
    L = ["## Plates (spec section 6.1)", "",
         f"{pl['solids']} solid(s), volume {pl['volume']:.12g} {units}³ (closed form {_f(pl['volume_closed_form'], '.12g')}); "
         f"`side = \"{pl['side']}\"` measured on {'the shell' if pl['side_reference'] == 'shell' else 'each surface'}'s normal"
         + (" (the first surface's normal, carried consistently across the shared rails)" if pl["side_reference"] == "shell" else "")
         + ".", "",
         "| surface | T | K | side | orientation | side on own normal | normal at centre | material goes | volume | closed form |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for x in pl["surfaces"]:
        n = ", ".join(f"{c:.4f}" for c in x["normal_at_centre"])
        L.append(f"| {x['surface']} | {x['thickness']:.6g} | {x['k_factor']:.4g} | {x['side']} | {x['orientation']:+d} | "
                 f"{x['side_on_own_normal']} | ({n}) | {x['material_goes']} | {x['volume']:.12g} | "
                 f"{_f(x['volume_closed_form'], '.12g')} |")
    L.append("")
    if pl.get("joints"):
        L += ["Joints along the shared rails (the plates are not trimmed): `gap` = the material lies on the convex side "
              "of the fold (an open wedge between the plates' end walls), `overlap` = on the concave side (the plates "
              "interpenetrate); distance = between the two plates' outside edges.", "",
              "| surfaces | kind | fold angle [deg] | outside-edge distance (max) | at |", "|---|---|---|---|---|"]
        for j in pl["joints"]:
            at = ", ".join(f"{c:.6g}" for c in j["at"])
            L.append(f"| {' / '.join(j['surfaces'])} | {j['kind']} | {j['fold_angle_deg_min']:.4g}–{j['fold_angle_deg_max']:.4g} | "
                     f"{j['outside_edge_distance_max']:.6g} {units} | ({at}) |")
        L.append("")
    return L
