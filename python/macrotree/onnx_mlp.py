"""A multilayer perceptron written as an ONNX model, with no dependency but numpy.

The `policy` leaf runs ONNX models; this writes the one kind the behaviour-cloning trainer
makes (``macrotree.bc``): named float32 inputs concatenated, normalised, a stack of
``MatMul``/``Add``/``Relu`` layers, un-normalised, plus an optional linear skip term from the
inputs (``action = mlp(x) + x @ skip``, so a model can predict offsets from the measured joints
and still output absolute set points), and an optional ``Reshape`` of the output into an action
chunk ``[1, k, 7]``. ONNX is protocol buffers; the few messages an MLP needs
(``ModelProto``, ``GraphProto``, ``NodeProto``, ``TensorProto``, ``ValueInfoProto``) are encoded
here by field number, as onnx.proto (IR version 8, opset 17) defines them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

F32 = npt.NDArray[np.float32]

#: ONNX IR version and default-domain opset of the written models (ONNX Runtime ≥ 1.14 reads them).
IR_VERSION = 8
OPSET = 17
_FLOAT = 1  # TensorProto.DataType.FLOAT
_INT64 = 7  # TensorProto.DataType.INT64


def _varint(n: int) -> bytes:
    out = bytearray()
    n &= (1 << 64) - 1
    while True:
        b = n & 0x7F
        n >>= 7
        if n:
            out.append(b | 0x80)
        else:
            out.append(b)
            return bytes(out)


def _key(num: int, wire: int) -> bytes:
    return _varint((num << 3) | wire)


def _int(num: int, value: int) -> bytes:
    return _key(num, 0) + _varint(value)


def _bytes(num: int, value: bytes) -> bytes:
    return _key(num, 2) + _varint(len(value)) + value


def _str(num: int, value: str) -> bytes:
    return _bytes(num, value.encode())


def _tensor(name: str, array: F32) -> bytes:
    a = np.ascontiguousarray(array, dtype="<f4")
    dims = b"".join(_int(1, d) for d in a.shape)
    return dims + _int(2, _FLOAT) + _str(8, name) + _bytes(9, a.tobytes())


def _int64_tensor(name: str, values: Sequence[int]) -> bytes:
    raw = np.asarray(values, dtype="<i8").tobytes()
    return _int(1, len(values)) + _int(2, _INT64) + _str(8, name) + _bytes(9, raw)


def _value_info(name: str, shape: Sequence[int]) -> bytes:
    dims = b"".join(_bytes(1, _int(1, d)) for d in shape)
    tensor_type = _int(1, _FLOAT) + _bytes(2, dims)
    return _str(1, name) + _bytes(2, _bytes(1, tensor_type))


def _node(op: str, inputs: Sequence[str], outputs: Sequence[str], attrs: bytes = b"") -> bytes:
    body = b"".join(_str(1, i) for i in inputs) + b"".join(_str(2, o) for o in outputs)
    return body + _str(3, outputs[0]) + _str(4, op) + attrs


def _int_attr(name: str, value: int) -> bytes:
    # AttributeProto: name = 1, i = 3, type = 20 (INT = 2).
    return _bytes(5, _str(1, name) + _int(3, value) + _int(20, 2))


@dataclass
class Mlp:
    """An MLP policy's numbers: layer weights (``W[i]`` of shape in × out) and biases, the
    input statistics (``x_mean``, ``x_std``), the output statistics (``y_mean``, ``y_std``) and
    an optional skip matrix (inputs × outputs)."""

    weights: list[F32]
    biases: list[F32]
    x_mean: F32
    x_std: F32
    y_mean: F32
    y_std: F32
    skip: F32 | None = None
    metadata: dict[str, str] = field(default_factory=dict)

    def forward(self, x: F32) -> F32:
        """The model's output for rows ``x`` (the concatenated inputs), as the graph computes it."""
        h = (x - self.x_mean) / self.x_std
        for i, (w, b) in enumerate(zip(self.weights, self.biases, strict=True)):
            h = h @ w + b
            if i < len(self.weights) - 1:
                h = np.maximum(h, 0.0)
        y = h * self.y_std + self.y_mean
        if self.skip is not None:
            y = y + x @ self.skip
        return y.astype(np.float32)


def to_onnx(
    mlp: Mlp, inputs: Sequence[tuple[str, int]], output: str = "action", chunk: int = 1
) -> bytes:
    """The ONNX model of ``mlp`` with float32 inputs ``[(name, width), ...]`` of shape
    ``[1, width]`` (concatenated in that order) and one output named ``output``: ``[1, n]``, or
    with ``chunk`` k > 1 the ``n`` values as a chunk ``[1, k, n / k]`` (row-major)."""
    nodes: list[bytes] = []
    inits: list[bytes] = []
    width = sum(n for _, n in inputs)
    if len(inputs) > 1:
        nodes.append(_node("Concat", [n for n, _ in inputs], ["x"], _int_attr("axis", 1)))
        x = "x"
    else:
        x = inputs[0][0]
    inits.append(_tensor("x_mean", mlp.x_mean.reshape(1, width)))
    inits.append(_tensor("x_std", mlp.x_std.reshape(1, width)))
    nodes.append(_node("Sub", [x, "x_mean"], ["x_centred"]))
    nodes.append(_node("Div", ["x_centred", "x_std"], ["h0"]))
    h = "h0"
    for i, (w, b) in enumerate(zip(mlp.weights, mlp.biases, strict=True)):
        inits.append(_tensor(f"W{i}", w))
        inits.append(_tensor(f"b{i}", b.reshape(1, -1)))
        nodes.append(_node("MatMul", [h, f"W{i}"], [f"m{i}"]))
        nodes.append(_node("Add", [f"m{i}", f"b{i}"], [f"a{i}"]))
        if i < len(mlp.weights) - 1:
            nodes.append(_node("Relu", [f"a{i}"], [f"h{i + 1}"]))
            h = f"h{i + 1}"
        else:
            h = f"a{i}"
    n_out = int(mlp.y_mean.size)
    inits.append(_tensor("y_std", mlp.y_std.reshape(1, n_out)))
    inits.append(_tensor("y_mean", mlp.y_mean.reshape(1, n_out)))
    nodes.append(_node("Mul", [h, "y_std"], ["y_scaled"]))
    if n_out % chunk:
        raise ValueError(f"{n_out} outputs do not make a chunk of {chunk}")
    flat = output if chunk == 1 else "flat"
    last = flat if mlp.skip is None else "y"
    nodes.append(_node("Add", ["y_scaled", "y_mean"], [last]))
    if mlp.skip is not None:
        inits.append(_tensor("skip", mlp.skip))
        nodes.append(_node("MatMul", [x, "skip"], ["skipped"]))
        nodes.append(_node("Add", ["y", "skipped"], [flat]))
    if chunk > 1:
        inits.append(_int64_tensor("chunk_shape", [1, chunk, n_out // chunk]))
        nodes.append(_node("Reshape", [flat, "chunk_shape"], [output]))
    graph = b"".join(_bytes(1, n) for n in nodes)
    graph += _str(2, "macrotree_mlp")
    graph += b"".join(_bytes(5, t) for t in inits)
    graph += b"".join(_bytes(11, _value_info(n, [1, w])) for n, w in inputs)
    out_shape = [1, n_out] if chunk == 1 else [1, chunk, n_out // chunk]
    graph += _bytes(12, _value_info(output, out_shape))
    model = _int(1, IR_VERSION) + _str(2, "macrotree") + _bytes(7, graph)
    model += _bytes(8, _str(1, "") + _int(2, OPSET))
    for k, v in sorted(mlp.metadata.items()):
        model += _bytes(14, _str(1, k) + _str(2, v))
    return model
