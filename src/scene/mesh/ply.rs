//! A PLY reader of our own: the header, then the `vertex` element (x, y, z;
//! nx, ny, nz; u, v or s, t) and the `face` element (a list
//! `vertex_indices` or `vertex_index`), in ASCII or binary of either byte
//! order; other elements and properties are read past. Our own rather than
//! `ply-rs` (unmaintained since 2020, and it allocates what a header
//! declares): every declared count is checked against the bytes left
//! before anything is allocated, so 2^31 faces declared in a tiny file is
//! one error line, not a huge allocation.

use super::data::{fan, Mesh};

type Res<T> = std::result::Result<T, String>;

/// The longest header read (real ones are a few hundred bytes).
const MAX_HEADER: usize = 64 << 10;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug)]
enum Prop {
    One(Scalar, String),
    /// A list: the count's type, the items' type, the name.
    List(Scalar, Scalar, String),
}

impl Prop {
    fn name(&self) -> &str {
        match self {
            Prop::One(_, n) | Prop::List(_, _, n) => n,
        }
    }

    /// The fewest bytes it takes in the body.
    fn min_bytes(&self, format: Format) -> u128 {
        match (format, self) {
            // a value and a separator
            (Format::Ascii, _) => 2,
            (_, Prop::One(s, _)) | (_, Prop::List(s, _, _)) => s.size() as u128,
        }
    }
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Prop>,
}

/// The header's format, elements, and where the body starts.
fn header(bytes: &[u8]) -> Res<(Format, Vec<Element>, usize)> {
    let head = &bytes[..bytes.len().min(MAX_HEADER)];
    let end = find(head, b"end_header")
        .ok_or("no `end_header` in the first 64 KiB; expected a PLY header")?;
    let body = end
        + 10
        + match head.get(end + 10..end + 12) {
            Some(b"\r\n") => 2,
            Some([b'\n', ..]) => 1,
            _ => return Err("`end_header` not followed by a line end".into()),
        };
    let text = std::str::from_utf8(&head[..end]).map_err(|_| "the header is not text")?;
    let mut lines = text.lines().map(str::trim);
    if lines.next() != Some("ply") {
        return Err("expected `ply` on the first line".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    _ => return Err(format!("unknown format `{}`", clip(f))),
                })
            }
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("element {}: bad count `{}`", clip(name), clip(count)))?,
                props: Vec::new(),
            }),
            ["property", rest @ ..] => {
                let el = elements.last_mut().ok_or("a property before any element")?;
                el.props.push(property(rest)?);
            }
            _ => return Err(format!("unexpected header line `{}`", clip(line))),
        }
    }
    let format = format.ok_or("no `format` line in the header")?;
    Ok((format, elements, body))
}

fn property(w: &[&str]) -> Res<Prop> {
    let ty =
        |s: &str| Scalar::parse(s).ok_or_else(|| format!("unknown property type `{}`", clip(s)));
    match w {
        ["list", c, i, name] => Ok(Prop::List(ty(c)?, ty(i)?, name.to_string())),
        [t, name] => Ok(Prop::One(ty(t)?, name.to_string())),
        _ => Err(format!(
            "bad property line `property {}`",
            clip(&w.join(" "))
        )),
    }
}

/// At most 40 characters of a file's text, for messages.
fn clip(s: &str) -> String {
    s.chars().take(40).flat_map(char::escape_default).collect()
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

/// The body's values in order, whatever the format.
struct Body<'a> {
    bytes: &'a [u8],
    pos: usize,
    format: Format,
}

impl Body<'_> {
    fn left(&self) -> usize {
        self.bytes.len() - self.pos
    }

    fn value(&mut self, s: Scalar) -> Res<f64> {
        if self.format == Format::Ascii {
            return self.token();
        }
        let n = s.size();
        let b = self
            .bytes
            .get(self.pos..self.pos + n)
            .ok_or("truncated: the body ends before its declared elements")?;
        self.pos += n;
        let mut a = [0u8; 8];
        if self.format == Format::Little {
            a[..n].copy_from_slice(b);
        } else {
            for (k, x) in b.iter().rev().enumerate() {
                a[k] = *x;
            }
        }
        let le2 = [a[0], a[1]];
        let le4 = [a[0], a[1], a[2], a[3]];
        Ok(match s {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes(le2) as f64,
            Scalar::U16 => u16::from_le_bytes(le2) as f64,
            Scalar::I32 => i32::from_le_bytes(le4) as f64,
            Scalar::U32 => u32::from_le_bytes(le4) as f64,
            Scalar::F32 => f32::from_le_bytes(le4) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    fn token(&mut self) -> Res<f64> {
        let b = self.bytes;
        while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err("truncated: the body ends before its declared elements".into());
        }
        let t = std::str::from_utf8(&b[start..self.pos]).unwrap_or("?");
        t.parse()
            .map_err(|_| format!("`{}` where a number was expected", clip(t)))
    }

    /// A list's length, checked against the bytes left.
    fn list_len(&mut self, count: Scalar, item: Scalar) -> Res<usize> {
        let n = self.value(count)?;
        let per = if self.format == Format::Ascii {
            2
        } else {
            item.size()
        };
        if !(n >= 0.0 && n.fract() == 0.0) || n * per as f64 > self.left() as f64 + 1.0 {
            return Err(format!(
                "truncated: a list of {n} values past the file's end"
            ));
        }
        Ok(n as usize)
    }
}

/// Where each wanted vertex value is among an item's scalars.
struct VertexLayout {
    pos: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
}

fn vertex_layout(el: &Element) -> Res<VertexLayout> {
    let at = |n: &str| {
        el.props
            .iter()
            .position(|p| matches!(p, Prop::One(_, m) if m == n))
    };
    let all3 = |a, b, c| Some([at(a)?, at(b)?, at(c)?]);
    let pos = all3("x", "y", "z").ok_or("the vertex element lacks one of x, y, z")?;
    let uv = [
        ("u", "v"),
        ("s", "t"),
        ("texture_u", "texture_v"),
        ("texture_s", "texture_t"),
    ]
    .iter()
    .find_map(|(u, v)| Some([at(u)?, at(v)?]));
    Ok(VertexLayout {
        pos,
        normal: all3("nx", "ny", "nz"),
        uv,
    })
}

/// Reads one item of `el`: its scalar values in order (lists read past),
/// and the one list `keep` names (if any).
fn item(
    b: &mut Body,
    el: &Element,
    keep: Option<usize>,
    row: &mut Vec<f64>,
    list: &mut Vec<u32>,
) -> Res<()> {
    row.clear();
    for (k, p) in el.props.iter().enumerate() {
        match *p {
            Prop::One(s, _) => row.push(b.value(s)?),
            Prop::List(c, i, _) => {
                let n = b.list_len(c, i)?;
                if Some(k) == keep {
                    list.clear();
                }
                for _ in 0..n {
                    let v = b.value(i)?;
                    if Some(k) == keep {
                        if !(v >= 0.0 && v.fract() == 0.0 && v <= u32::MAX as f64) {
                            return Err(format!("vertex index {v}; expected a whole number >= 0"));
                        }
                        list.push(v as u32);
                    }
                }
            }
        }
    }
    Ok(())
}

/// Parses a whole PLY file.
pub fn parse(bytes: &[u8]) -> Res<Mesh> {
    let (format, elements, start) = header(bytes)?;
    let mut b = Body {
        bytes,
        pos: start,
        format,
    };
    let mut mesh = Mesh::default();
    let mut row = Vec::new();
    let mut list = Vec::new();
    for el in &elements {
        if el.count > 0 && el.props.is_empty() {
            return Err(format!("element {} has no properties", clip(&el.name)));
        }
        let least: u128 =
            el.props.iter().map(|p| p.min_bytes(format)).sum::<u128>() * el.count as u128;
        if least > b.left() as u128 + 1 {
            return Err(format!(
                "declares {} {} elements, more than its {} bytes can hold",
                el.count,
                clip(&el.name),
                bytes.len()
            ));
        }
        // within the file's size, checked above
        let n = el.count as usize;
        match el.name.as_str() {
            "vertex" => {
                let lay = vertex_layout(el)?;
                mesh.positions.reserve(n);
                for _ in 0..n {
                    item(&mut b, el, None, &mut row, &mut list)?;
                    mesh.positions.push(lay.pos.map(|k| row[k]));
                    if let Some(nk) = lay.normal {
                        mesh.normals.push(nk.map(|k| row[k]));
                    }
                    if let Some(uk) = lay.uv {
                        mesh.texcoords.push(uk.map(|k| row[k]));
                    }
                }
            }
            "face" => {
                let keep = el
                    .props
                    .iter()
                    .position(|p| {
                        matches!(p, Prop::List(..))
                            && matches!(p.name(), "vertex_indices" | "vertex_index")
                    })
                    .ok_or("the face element has no list `vertex_indices`")?;
                mesh.triangles.reserve(n);
                for f in 0..n {
                    item(&mut b, el, Some(keep), &mut row, &mut list)?;
                    fan(&list, f, &mut mesh.triangles)?;
                }
            }
            _ => {
                for _ in 0..n {
                    item(&mut b, el, None, &mut row, &mut list)?;
                }
            }
        }
    }
    Ok(mesh)
}
