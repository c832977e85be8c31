"""The learned model's file, as lib/learned/model_file.c reads it (docs/model.md, "The file").

Little-endian: magic, format version, descriptor layout, neighbours, inputs, the training
manifest's BLAKE2b-256, the stage count; per stage its layer count and per layer (in, out,
activation, float32 weights row-major, float32 biases); last a BLAKE2b-256 of all bytes before.
"""
import hashlib
import struct

import numpy as np

MAGIC = b"RSNN\r\n\x1a\n"
FORMAT_VERSION = 1
LAYOUT = 1
NEIGHBOURS = 32
INPUTS = NEIGHBOURS * 7 + 3 * 4 + 3 + 1


def encode(stages, manifest_digest):
    """stages: a list of stages, each a list of (weight (out, in), bias (out,), activation)."""
    assert len(manifest_digest) == 32
    out = bytearray(MAGIC)
    out += struct.pack("<4I", FORMAT_VERSION, LAYOUT, NEIGHBOURS, INPUTS)
    out += manifest_digest
    out += struct.pack("<I", len(stages))
    for layers in stages:
        out += struct.pack("<I", len(layers))
        for weight, bias, activation in layers:
            weight = np.ascontiguousarray(weight, dtype="<f4")
            bias = np.ascontiguousarray(bias, dtype="<f4")
            rows, cols = weight.shape
            assert bias.shape == (rows,)
            out += struct.pack("<3I", cols, rows, activation)
            out += weight.tobytes() + bias.tobytes()
    out += hashlib.blake2b(bytes(out), digest_size=32).digest()
    return bytes(out)


def decode(data):
    """The stages and manifest digest of a model file's bytes (checked as the C reader does)."""
    if data[:8] != MAGIC:
        raise ValueError("not an rsmooth model")
    if hashlib.blake2b(data[:-32], digest_size=32).digest() != data[-32:]:
        raise ValueError("checksum does not match")
    version, layout, neighbours, inputs = struct.unpack_from("<4I", data, 8)
    if (version, layout, neighbours, inputs) != (FORMAT_VERSION, LAYOUT, NEIGHBOURS, INPUTS):
        raise ValueError("another format or layout")
    manifest = data[24:56]
    (count,) = struct.unpack_from("<I", data, 56)
    at, stages = 60, []
    for _ in range(count):
        (layer_count,) = struct.unpack_from("<I", data, at)
        at += 4
        layers = []
        for _ in range(layer_count):
            cols, rows, activation = struct.unpack_from("<3I", data, at)
            at += 12
            weight = np.frombuffer(data, "<f4", rows * cols, at).reshape(rows, cols)
            at += 4 * rows * cols
            bias = np.frombuffer(data, "<f4", rows, at)
            at += 4 * rows
            layers.append((weight, bias, activation))
        stages.append(layers)
    return stages, manifest


def write(path, stages, manifest_digest):
    """Writes the model whole: to a temporary name beside `path`, then renamed over it."""
    import os

    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(encode(stages, manifest_digest))
    os.replace(tmp, path)
