"""The model card's plots, as SVG (no plotting library): the training loss by epoch of each stage
and fold; the left-out normal error (theta) by noise class, learned against the hand-fitted
stage; and the left-out facets' normal error by noise class, of what the guided cycles leave, of
the model's normals and of those capped (evaluate.py's figures).

    python train/plots.py OUT docs/img
"""
import json
import os
import sys

import numpy as np

COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd"]


def svg(width, height, body):
    return (f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
            f'font-family="sans-serif" font-size="11">\n<rect width="100%" height="100%" '
            f'fill="white"/>\n{body}</svg>\n')


def loss_plot(models):
    w, h, left, top, pw, ph = 560, 300, 50, 20, 470, 230
    curves = {}
    for stage in (1, 2):
        for fold in ("0", "1", "2", "3", "all"):
            path = os.path.join(models, f"stage{stage}-fold{fold}.npz")
            if os.path.exists(path):
                history = json.loads(str(np.load(path)["history"]))
                curves[(stage, fold)] = [e["loss"] for e in history]
    if not curves:
        return None
    lo = min(min(c) for c in curves.values())
    hi = max(max(c) for c in curves.values())
    n = max(len(c) for c in curves.values())
    body = [f'<text x="{left}" y="14">training loss (mean distance between unit normals) by '
            'epoch; solid: stage 1, dashed: stage 2</text>']
    for (stage, fold), c in curves.items():
        pts = " ".join(f"{left + pw * i / max(n - 1, 1):.1f},"
                       f"{top + ph * (1 - (v - lo) / (hi - lo or 1)):.1f}" for i, v in enumerate(c))
        colour = COLOURS[["0", "1", "2", "3", "all"].index(fold)]
        dash = ' stroke-dasharray="5,3"' if stage == 2 else ""
        body.append(f'<polyline points="{pts}" fill="none" stroke="{colour}"{dash}/>')
    for k, fold in enumerate(["0", "1", "2", "3", "all"]):
        body.append(f'<text x="{left + 70 * k}" y="{top + ph + 30}" fill="{COLOURS[k]}">'
                    f'fold {fold}</text>')
    body.append(f'<text x="5" y="{top + 8}">{hi:.3f}</text>'
                f'<text x="5" y="{top + ph}">{lo:.3f}</text>')
    body.append(f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" '
                'stroke="#888"/>')
    return svg(w, h, "\n".join(body) + "\n")


def bars(table, series, title):
    """Grouped bars per noise class: series is [(label, value of a row, colour)]."""
    keys = [k for k in table if all(get(table[k]) is not None for _, get, _ in series)]
    step = 24 * len(series) + 26
    w, h, left, top, ph = 80 + step * len(keys), 300, 40, 30, 210
    top_value = max(get(table[k]) for k in keys for _, get, _ in series) or 1
    legend = ", ".join(f"{NAMES[colour]} {label}" for label, _, colour in series)
    body = [f'<text x="10" y="14">{title}: {legend}</text>']
    for i, k in enumerate(keys):
        x = left + step * i
        for j, (_, get, colour) in enumerate(series):
            v = get(table[k])
            bh = ph * v / top_value
            body.append(f'<rect x="{x + 22 * j}" y="{top + ph - bh:.1f}" width="20" '
                        f'height="{bh:.1f}" fill="{colour}"/>')
            body.append(f'<text x="{x + 22 * j}" y="{top + ph - bh - 3:.1f}" font-size="9">'
                        f'{v:.1f}</text>')
        body.append(f'<text x="{x}" y="{top + ph + 14}" font-size="10">{k}</text>')
    return svg(w, h, "\n".join(body) + "\n")


NAMES = {"#999": "grey", "#1f77b4": "blue", "#ff7f0e": "orange"}


def class_plot(evaluation):
    table = json.load(open(evaluation))["by_class"]
    return bars(table, [("the hand-fitted stage", lambda r: r["theta_hand"], "#999"),
                        ("the learned", lambda r: r["theta_learned"], "#1f77b4")],
                "left-out mean theta (degrees) by noise class")


def facet_plot(evaluation):
    """Facet by facet: what the guided cycles leave, the model's normals, those capped."""
    table = json.load(open(evaluation))["by_class"]
    return bars(table, [("after the guided cycles", lambda r: r.get("normals", {}).get("staged"),
                         "#999"),
                        ("the model's normals", lambda r: r.get("normals", {}).get("learned"),
                         "#1f77b4"),
                        ("capped", lambda r: r.get("normals", {}).get("capped"), "#ff7f0e")],
                "left-out mean facet normal error (degrees) by noise class")


def main():
    out, img = sys.argv[1], sys.argv[2]
    plot = loss_plot(os.path.join(out, "models"))
    if plot:
        with open(os.path.join(img, "model-loss.svg"), "w") as f:
            f.write(plot)
    evaluation = os.path.join(out, "evaluation.json")
    if os.path.exists(evaluation):
        with open(os.path.join(img, "model-left-out.svg"), "w") as f:
            f.write(class_plot(evaluation))
        with open(os.path.join(img, "model-facets.svg"), "w") as f:
            f.write(facet_plot(evaluation))


if __name__ == "__main__":
    main()
