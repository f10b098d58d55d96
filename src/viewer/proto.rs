//! MeshCat wire messages: msgpack maps with string keys, typed arrays as msgpack ext values,
//! column-major 4×4 matrices.
//!
//! Every server→browser command is one msgpack map with a `type` field (see
//! `docs/viewer.md` and the design note). Absent fields are omitted, never `nil`.

use rmpv::Value;
use tungstenite::Bytes;

/// msgpack-lite ext code of a `Uint32Array`.
pub const EXT_UINT32: i8 = 0x16;
/// msgpack-lite ext code of a `Float32Array`.
pub const EXT_FLOAT32: i8 = 0x17;

/// A 4×4 homogeneous transform in three.js order: **column-major**, 16 numbers.
pub type Mat4 = [f64; 16];

/// The identity transform.
pub const IDENTITY: Mat4 = [
    1.0, 0.0, 0.0, 0.0, //
    0.0, 1.0, 0.0, 0.0, //
    0.0, 0.0, 1.0, 0.0, //
    0.0, 0.0, 0.0, 1.0,
];

/// A msgpack string value.
pub fn s(text: &str) -> Value {
    Value::from(text)
}

/// A msgpack map with string keys, in the given order.
pub fn map(fields: Vec<(&str, Value)>) -> Value {
    Value::Map(fields.into_iter().map(|(k, v)| (s(k), v)).collect())
}

/// A `Float32Array` as msgpack ext 0x17 (little-endian).
pub fn f32_ext(values: &[f32]) -> Value {
    let mut bytes = Vec::with_capacity(values.len() * 4);
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    Value::Ext(EXT_FLOAT32, bytes)
}

/// A `Uint32Array` as msgpack ext 0x16 (little-endian).
pub fn u32_ext(values: &[u32]) -> Value {
    let mut bytes = Vec::with_capacity(values.len() * 4);
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    Value::Ext(EXT_UINT32, bytes)
}

/// A plain msgpack array of float64 numbers.
pub fn f64_array(values: &[f64]) -> Value {
    Value::Array(values.iter().map(|&v| Value::F64(v)).collect())
}

/// Encodes one value as msgpack bytes (one websocket binary frame).
pub fn encode(value: &Value) -> Bytes {
    let mut buf = Vec::with_capacity(256);
    rmpv::encode::write_value(&mut buf, value).expect("writing msgpack to a Vec cannot fail");
    Bytes::from(buf)
}

/// Normalises a scene path the way the viewer reads it: `/`-separated, empty segments dropped,
/// always starting with `/` (the root is `/`).
pub fn normalize_path(path: &str) -> String {
    let mut out = String::with_capacity(path.len() + 1);
    for seg in path.split('/').filter(|seg| !seg.is_empty()) {
        out.push('/');
        out.push_str(seg);
    }
    if out.is_empty() {
        out.push('/');
    }
    out
}

/// `set_object`: puts a three.js JSON object (ObjectLoader format 4.5) at `path/<object>`.
pub fn set_object(path: &str, object: Value) -> Value {
    map(vec![
        ("type", s("set_object")),
        ("path", s(path)),
        ("object", object),
    ])
}

/// `set_transform`: the transform of the group at `path`, 16 column-major float64 numbers.
pub fn set_transform(path: &str, matrix: &Mat4) -> Value {
    map(vec![
        ("type", s("set_transform")),
        ("path", s(path)),
        ("matrix", f64_array(matrix)),
    ])
}

/// The bytes of [`set_transform`] written directly (no intermediate value tree): the same
/// encoding, several times faster, for the per-frame pose path.
pub fn encode_set_transform(path: &str, matrix: &Mat4) -> Bytes {
    let mut buf = Vec::with_capacity(48 + path.len() + 16 * 9);
    buf.push(0x83); // fixmap, 3 entries
    write_str(&mut buf, "type");
    write_str(&mut buf, "set_transform");
    write_str(&mut buf, "path");
    write_str(&mut buf, path);
    write_str(&mut buf, "matrix");
    buf.extend_from_slice(&[0xdc, 0x00, 0x10]); // array16, 16 entries
    for v in matrix {
        buf.push(0xcb); // float64, big-endian
        buf.extend_from_slice(&v.to_be_bytes());
    }
    Bytes::from(buf)
}

/// A msgpack string header + bytes (shortest form).
fn write_str(buf: &mut Vec<u8>, text: &str) {
    let n = text.len();
    if n < 32 {
        buf.push(0xa0 | n as u8);
    } else if n < 256 {
        buf.extend_from_slice(&[0xd9, n as u8]);
    } else if n < 65536 {
        buf.push(0xda);
        buf.extend_from_slice(&(n as u16).to_be_bytes());
    } else {
        buf.push(0xdb);
        buf.extend_from_slice(&(n as u32).to_be_bytes());
    }
    buf.extend_from_slice(text.as_bytes());
}

/// `delete`: removes the subtree at `path`.
pub fn delete(path: &str) -> Value {
    map(vec![("type", s("delete")), ("path", s(path))])
}

/// `set_property`: sets one property (e.g. `visible`, `position`, `color`) of the node at `path`.
pub fn set_property(path: &str, property: &str, value: Value) -> Value {
    map(vec![
        ("type", s("set_property")),
        ("path", s(path)),
        ("property", s(property)),
        ("value", value),
    ])
}

/// `capture_image`: the viewer renders and answers with a text frame
/// `{"type":"img","data":"data:image/png;base64,…"}`.
pub fn capture_image() -> Value {
    map(vec![("type", s("capture_image"))])
}

/// `set_animation` with `options` (`play`, `loopMode`, `clampWhenFinished`, …).
pub fn set_animation(animations: Vec<Value>, options: Value) -> Value {
    map(vec![
        ("type", s("set_animation")),
        ("animations", Value::Array(animations)),
        ("options", options),
    ])
}

/// A rigid transform from a position and a MuJoCo quaternion `(w, x, y, z)`, column-major.
pub fn mat_from_pos_quat(pos: [f64; 3], quat: [f64; 4]) -> Mat4 {
    let [w, x, y, z] = quat;
    let n = (w * w + x * x + y * y + z * z).sqrt();
    let (w, x, y, z) = if n > 0.0 {
        (w / n, x / n, y / n, z / n)
    } else {
        (1.0, 0.0, 0.0, 0.0)
    };
    // Row-major rotation entries r[row][col].
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let mut m = IDENTITY;
    for (row, r_row) in r.iter().enumerate() {
        for (col, &v) in r_row.iter().enumerate() {
            m[col * 4 + row] = v;
        }
    }
    m[12] = pos[0];
    m[13] = pos[1];
    m[14] = pos[2];
    m
}

/// A rigid transform from a position and MuJoCo's **row-major** 3×3 `xmat`, column-major.
pub fn mat_from_pos_xmat(pos: [f64; 3], xmat: [f64; 9]) -> Mat4 {
    [
        xmat[0], xmat[3], xmat[6], 0.0, //
        xmat[1], xmat[4], xmat[7], 0.0, //
        xmat[2], xmat[5], xmat[8], 0.0, //
        pos[0], pos[1], pos[2], 1.0,
    ]
}

/// A diagonal scale, column-major.
pub fn mat_scale(sx: f64, sy: f64, sz: f64) -> Mat4 {
    let mut m = IDENTITY;
    m[0] = sx;
    m[5] = sy;
    m[10] = sz;
    m
}

/// Rotation by +90° about X: maps three.js's Y axis (cylinders) onto Z (MuJoCo's axis).
pub fn mat_rot_x90() -> Mat4 {
    [
        1.0, 0.0, 0.0, 0.0, //
        0.0, 0.0, 1.0, 0.0, //
        0.0, -1.0, 0.0, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    ]
}

/// Product `a · b` of two column-major matrices.
pub fn mat_mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut out = [0.0; 16];
    for col in 0..4 {
        for row in 0..4 {
            out[col * 4 + row] = (0..4).map(|k| a[k * 4 + row] * b[col * 4 + k]).sum();
        }
    }
    out
}

/// Packs an `[r, g, b]` colour in 0..1 as the integer `0xRRGGBB` three.js materials take.
pub fn color_hex(rgb: [f32; 3]) -> u32 {
    let c = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u32;
    (c(rgb[0]) << 16) | (c(rgb[1]) << 8) | c(rgb[2])
}
