"""Trains one cascade stage of the learned normals (JAX, on the CPU, fixed seeds).

    python train/train.py CACHE OUT --stage S [--leave-out FOLD] [--epochs E]

A perceptron on each facet's descriptor (CACHE/stage{S}.npz, train/dataset.py) predicts the
residual between the facet's own normal and its true normal, both in the descriptor's frame;
the loss is the distance between the predicted unit normal and the true one. Training
sees each patch mirrored across the frame's x and y axes at random (a mirrored patch is as real a
patch, and it covers the frames whose sign rules are unstable). Inputs are standardised, and
the standardisation is folded into the first layer when saved. --leave-out F trains without the
shapes of fold F and reports the error on them each epoch. A checkpoint after every epoch
(OUT/stage{S}-fold{F}.ckpt.npz) lets a stopped run resume where it was.
Writes OUT/stage{S}-fold{F}.npz (F "all" without --leave-out): the layers and the history.
"""
import argparse
import json
import os
import time

import jax
import jax.numpy as jnp
import numpy as np

HIDDEN = (176, 176, 96)
BATCH = 512
NEIGHBOURS, PER, FILTERED = 32, 7, 4


def mirror_signs():
    """Per descriptor entry: which frame axis it is a component of (0 x, 1 y, -1 none)."""
    axis = np.full(NEIGHBOURS * PER + 3 * FILTERED + 4, -1)
    for k in range(NEIGHBOURS):
        for v in (0, 3):
            axis[k * PER + v], axis[k * PER + v + 1] = 0, 1
    for w in range(FILTERED):
        base = NEIGHBOURS * PER + 3 * w
        axis[base], axis[base + 1] = 0, 1
    return axis


def init(key, sizes):
    params = []
    for i, (a, b) in enumerate(zip(sizes[:-1], sizes[1:])):
        key, sub = jax.random.split(key)
        scale = np.sqrt(2.0 / a) if i < len(sizes) - 2 else 0.01 / np.sqrt(a)
        params.append((jax.random.normal(sub, (b, a), jnp.float32) * scale,
                       jnp.zeros(b, jnp.float32)))
    return params


def forward(params, x):
    for i, (w, b) in enumerate(params):
        x = x @ w.T + b
        if i < len(params) - 1:
            x = jax.nn.relu(x)
    return x


def predict_unit(params, x_std, own):
    v = own + forward(params, x_std)
    return v / jnp.maximum(jnp.linalg.norm(v, axis=1, keepdims=True), 1e-12)


def loss_fn(params, x_std, own, y, weight):
    """The mean distance between predicted and true unit normals (not squared: the few facets the
    stage before left far off, and cannot be mended from their patch, do not drown the many it
    left near, which a small correction improves)."""
    d = predict_unit(params, x_std, own) - y
    return jnp.sum(weight * jnp.sqrt(jnp.sum(d * d, axis=1) + 1e-8)) / jnp.sum(weight)


@jax.jit
def adam_step(params, m, v, t, lr, x_std, own, y, weight):
    loss, grads = jax.value_and_grad(loss_fn)(params, x_std, own, y, weight)
    b1, b2 = 0.9, 0.999
    m = jax.tree_util.tree_map(lambda a, g: b1 * a + (1 - b1) * g, m, grads)
    v = jax.tree_util.tree_map(lambda a, g: b2 * a + (1 - b2) * g * g, v, grads)
    corr = jnp.sqrt(1 - b2 ** t) / (1 - b1 ** t)
    params = jax.tree_util.tree_map(lambda p, a, b: p - lr * corr * a / (jnp.sqrt(b) + 1e-8),
                                    params, m, v)
    return params, m, v, loss


def angles(params, x_std, own, y):
    out = []
    for s in range(0, len(x_std), 65536):
        p = np.asarray(predict_unit(params, x_std[s:s + 65536], own[s:s + 65536]))
        out.append(np.degrees(np.arccos(np.clip(np.sum(p * y[s:s + 65536], 1), -1, 1))))
    return np.concatenate(out) if out else np.zeros(0)


def fold_layers(params, mean, std):
    """The layers as the C library runs them on raw descriptors: the standardisation folded in."""
    layers = [(np.asarray(w, np.float64), np.asarray(b, np.float64)) for w, b in params]
    w0, b0 = layers[0]
    layers[0] = (w0 / std, b0 - (w0 / std) @ mean)
    return [(w.astype(np.float32), b.astype(np.float32), 1 if i < len(layers) - 1 else 0)
            for i, (w, b) in enumerate(layers)]


def load(cache, stage, leave_out):
    """The stage's data: stage{S}.npz, or for a stage after the first the fold's own
    (stage{S}-fold{F}.npz: made from the fold's model of the stage before)."""
    own = os.path.join(cache, f"stage{stage}-fold{'all' if leave_out is None else leave_out}.npz")
    data = np.load(own if stage > 1 else os.path.join(cache, f"stage{stage}.npz"))
    cases = json.load(open(os.path.join(cache, "manifest.json")))["cases"]
    fold = np.array([c["fold"] for c in cases])[data["case"]]
    kind = np.array([c["class"] for c in cases])[data["case"]]
    x, y = data["x"], data["y"] / np.linalg.norm(data["y"], axis=1, keepdims=True)
    held = fold == leave_out if leave_out is not None else np.zeros(len(x), bool)
    return x, y.astype(np.float32), held, kind, data["sharp"]


def train(args):
    tag = f"stage{args.stage}-fold{'all' if args.leave_out is None else args.leave_out}"
    x, y, held, kind, sharp = load(args.cache, args.stage, args.leave_out)
    xt, yt = x[~held], y[~held]
    mean, std = xt.mean(0).astype(np.float64), np.maximum(xt.std(0), 1e-3).astype(np.float64)
    standard = lambda a: ((a - mean) / std).astype(np.float32)  # noqa: E731
    xv, yv, kv = standard(x[held]), y[held], kind[held]
    xs = standard(xt)
    own = xt[:, 0:3]
    weight = np.ones(len(xt), np.float32)
    axis = mirror_signs()
    ckpt = os.path.join(args.out, tag + ".ckpt.npz")
    rng = np.random.default_rng(args.seed)
    hidden = tuple(int(h) for h in args.hidden.split(",")) if args.hidden else HIDDEN
    params = init(jax.random.PRNGKey(args.seed), (x.shape[1], *hidden, 3))
    m = jax.tree_util.tree_map(jnp.zeros_like, params)
    v = jax.tree_util.tree_map(jnp.zeros_like, params)
    history, start, t = [], 0, 0
    if os.path.exists(ckpt):
        c = np.load(ckpt, allow_pickle=True)
        params, m, v = (jax.tree_util.tree_map(jnp.asarray, c[k].tolist()) for k in "pmv")
        history, start, t = c["history"].tolist(), int(c["epoch"]), int(c["t"])
        rng = np.random.default_rng([args.seed, start])
        print(f"{tag}: resumed after epoch {start}")
    steps_per_epoch = len(xs) // BATCH
    total = steps_per_epoch * args.epochs
    for epoch in range(start, args.epochs):
        t0, order, losses = time.time(), rng.permutation(len(xs)), []
        flips = rng.integers(0, 2, size=(len(xs), 2)) * -2 + 1
        for s in range(steps_per_epoch):
            idx = order[s * BATCH:(s + 1) * BATCH]
            sign = np.where(axis[None, :] == 0, flips[idx, 0:1],
                            np.where(axis[None, :] == 1, flips[idx, 1:2], 1)).astype(np.float32)
            tsign = np.stack([flips[idx, 0], flips[idx, 1], np.ones(len(idx))], 1).astype(
                np.float32)
            raw = xt[idx] * sign
            t += 1
            lr = args.lr * 0.5 * (1 + np.cos(np.pi * min(t / total, 1.0)))
            params, m, v, loss = adam_step(params, m, v, t, lr, standard(raw), raw[:, 0:3],
                                           yt[idx] * tsign, weight[idx])
            losses.append(float(loss))
        entry = {"epoch": epoch + 1, "loss": float(np.mean(losses)), "seconds": time.time() - t0}
        if len(xv):
            a = angles(params, xv, x[held][:, 0:3], yv)
            entry["held_angle"] = float(a.mean())
            entry["held_by_class"] = {k: float(a[kv == k].mean()) for k in sorted(set(kv))}
            entry["held_input_angle"] = float(np.degrees(np.arccos(np.clip(
                np.sum(x[held][:, 0:3] * yv, 1), -1, 1))).mean())
        history.append(entry)
        print(json.dumps(entry), flush=True)
        np.savez(ckpt + ".tmp.npz", p=np.array(jax.tree_util.tree_map(np.asarray, params),
                                               dtype=object),
                 m=np.array(jax.tree_util.tree_map(np.asarray, m), dtype=object),
                 v=np.array(jax.tree_util.tree_map(np.asarray, v), dtype=object),
                 history=np.array(history, dtype=object), epoch=epoch + 1, t=t)
        os.replace(ckpt + ".tmp.npz", ckpt)
    layers = fold_layers(params, mean, std)
    out = os.path.join(args.out, tag + ".npz")
    np.savez(out, **{f"w{i}": w for i, (w, b, a) in enumerate(layers)},
             **{f"b{i}": b for i, (w, b, a) in enumerate(layers)},
             history=json.dumps(history))
    print(f"{out}: {sum(w.size + b.size for w, b, a in layers)} parameters")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cache")
    ap.add_argument("out")
    ap.add_argument("--stage", type=int, default=1)
    ap.add_argument("--leave-out", type=int)
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--hidden", help="the hidden layers' widths (default: 176,176,96)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    train(args)


if __name__ == "__main__":
    main()
