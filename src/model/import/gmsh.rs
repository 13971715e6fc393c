//! A body of finite elements from a Gmsh MSH file (`shape = "mesh"`), format
//! 4.1, ASCII or binary, read by the `mshio` crate (the MSH 4.1 reader of
//! crates.io; its `$Entities`, `$Nodes` and `$Elements`). What it leaves, this
//! file does: the `$MeshFormat` line is checked first (a version other than
//! 4.1 is named, and a header the crate would not take is refused before it
//! sees it), and the `$PhysicalNames` section (ASCII in both forms) is read
//! here, for `physical = "name"`. The body takes the elements of its
//! dimension (2D: 3-node triangles, 4-node quadrilaterals; 3D: 4-node
//! tetrahedra, 8-node hexahedra), of the entities in its physical group if it
//! names one; elements of a lower dimension (boundary lines, faces, points) are
//! passed over, one of another type of its dimension is refused by its tag.
//!
//! Node tags: mshio keeps a block's tags only where the file's tags are sparse;
//! where they run without gaps from the smallest it numbers the nodes in file
//! order from there, as Gmsh writes them, and so does this file.

use crate::model::mesh::{Element, ElementKind, ElementMesh};
use crate::scene::{PhysicalGroup, Quadrature};
use mshio::{ElementType, MshFile};
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// What the body asks of the file.
pub struct Select<'a> {
    /// The scene's spatial dimension: the elements' dimension.
    pub dim: usize,
    pub physical: Option<&'a PhysicalGroup>,
    pub quadrature: Quadrature,
    /// The grid's corners: every node must lie in [min, max].
    pub grid: (&'a [f64], &'a [f64]),
}

type Msh = MshFile<u64, i32, f64>;

/// Read the mesh of `path` (`shown` names it in messages) for a body.
pub fn read(path: &Path, shown: &str, select: &Select) -> Result<ElementMesh, String> {
    let bytes =
        std::fs::read(path).map_err(|e| format!("cannot read the Gmsh file {shown}: {e}"))?;
    let at = |m: String| format!("{shown}{m}");
    let binary = mesh_format(&bytes).map_err(at)?;
    let names = physical_names(&bytes).map_err(at)?;
    let msh = parse(&bytes, binary).map_err(at)?;
    let entities = entities(&msh, &names, select).map_err(|m| format!("{shown}: {m}"))?;
    let mesh = elements(&msh, &entities, select).map_err(|m| format!("{shown}: {m}"))?;
    mesh.check().map_err(|m| format!("{shown}: {m}"))?;
    inside_grid(&mesh, select.grid).map_err(|m| format!("{shown}: {m}"))?;
    Ok(mesh)
}

/// The `$MeshFormat` line: version 4.1, file type 0 (ASCII) or 1 (binary),
/// data size 4 or 8; whether the file is binary. Errors start with `:line: `.
fn mesh_format(bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(256)]);
    let mut lines = text
        .lines()
        .enumerate()
        .skip_while(|(_, l)| l.trim().is_empty());
    match lines.next() {
        Some((_, l)) if l.trim() == "$MeshFormat" => {}
        _ => return Err(": not a Gmsh MSH file: it does not start with `$MeshFormat`".into()),
    }
    let (n, line) = lines.next().ok_or(": the file ends after `$MeshFormat`")?;
    let words: Vec<&str> = line.split_whitespace().collect();
    let line_no = n + 1;
    if words.len() != 3 {
        return Err(format!(
            ":{line_no}: `{line}`: expected the version, the file type and the data size"
        ));
    }
    if words[0] != "4.1" {
        return Err(format!(
            ":{line_no}: MSH format version {}: only version 4.1 is read (Gmsh: \
             Mesh.MshFileVersion = 4.1, or `-format msh41`)",
            words[0]
        ));
    }
    if !matches!(words[1], "0" | "1") || !matches!(words[2], "4" | "8") {
        return Err(format!(
            ":{line_no}: `{line}`: the file type must be 0 (ASCII) or 1 (binary) and the \
             data size 4 or 8"
        ));
    }
    Ok(words[1] == "1")
}

/// The `$PhysicalNames` section: (dimension, tag) → name. Errors start with
/// `:line: `.
fn physical_names(bytes: &[u8]) -> Result<HashMap<(i32, i32), String>, String> {
    let mut names = HashMap::new();
    let Some(start) = find_line(bytes, b"$PhysicalNames") else {
        return Ok(names);
    };
    let first = 1 + bytes[..start].iter().filter(|&&b| b == b'\n').count();
    let rest = String::from_utf8_lossy(&bytes[start..]);
    let mut lines = rest.lines().enumerate().skip(1);
    let bad =
        |k: usize, l: &str| format!(":{}: `{l}`: expected `dimension tag \"name\"`", first + k);
    let (k, l) = lines.next().ok_or(": the file ends in $PhysicalNames")?;
    let count: usize = l.trim().parse().map_err(|_| bad(k, l))?;
    for _ in 0..count {
        let (k, l) = lines.next().ok_or(": the file ends in $PhysicalNames")?;
        let mut parts = l.trim().splitn(3, char::is_whitespace);
        let dim = parts.next().and_then(|w| w.parse().ok());
        let tag = parts.next().and_then(|w| w.parse().ok());
        let name = parts.next().map(|w| w.trim());
        match (dim, tag, name) {
            (Some(d), Some(t), Some(n))
                if n.len() >= 2 && n.starts_with('"') && n.ends_with('"') =>
            {
                names.insert((d, t), n[1..n.len() - 1].to_string());
            }
            _ => return Err(bad(k, l)),
        }
    }
    Ok(names)
}

/// The offset of the line that is `word` (from its start), if any.
fn find_line(bytes: &[u8], word: &[u8]) -> Option<usize> {
    let mut start = 0;
    for line in bytes.split(|&b| b == b'\n') {
        let trimmed = line.strip_suffix(b"\r").unwrap_or(line);
        if trimmed == word {
            return Some(start);
        }
        start += line.len() + 1;
    }
    None
}

/// The file through mshio; its error at the line (ASCII) or byte (binary) where
/// it stopped, with what it was reading. A panic inside the crate (none is known
/// once `mesh_format` has passed) becomes an error too.
fn parse(bytes: &[u8], binary: bool) -> Result<Msh, String> {
    let parsed = std::panic::catch_unwind(|| {
        mshio::parse_msh_bytes(bytes).map_err(|e| {
            let at = e.backtrace.first().map_or(bytes.len(), |(rest, _)| {
                bytes.len().saturating_sub(rest.len())
            });
            let what: Vec<String> = (e.backtrace.iter().rev())
                .filter_map(|(_, k)| k.context().map(str::to_string))
                .collect();
            // A kind that is only a context would repeat the last one.
            let why = match e.first_msh_error() {
                Some(k) if k.context().is_none() => k.to_string(),
                _ => "not what the format has there".to_string(),
            };
            (at, what.join(", in "), why)
        })
    });
    match parsed {
        Ok(Ok(msh)) => Ok(msh),
        Ok(Err((at, what, why))) => {
            let place = match binary {
                true => format!(": byte {at}"),
                false => format!(
                    ":{}",
                    1 + bytes[..at].iter().filter(|&&b| b == b'\n').count()
                ),
            };
            Err(format!("{place}: in {what}: {why}"))
        }
        Err(_) => Err(": the MSH reader (mshio) failed on this file".into()),
    }
}

/// The tags of the entities of the body's dimension whose elements it takes:
/// all, or those of its physical group.
fn entities(
    msh: &Msh,
    names: &HashMap<(i32, i32), String>,
    select: &Select,
) -> Result<Option<HashSet<i32>>, String> {
    let Some(group) = select.physical else {
        return Ok(None);
    };
    let dim = select.dim as i32;
    let of_dim: Vec<(i32, Vec<i32>)> = match &msh.data.entities {
        Some(e) if dim == 2 => e
            .surfaces
            .iter()
            .map(|s| (s.tag, s.physical_tags.clone()))
            .collect(),
        Some(e) => e
            .volumes
            .iter()
            .map(|v| (v.tag, v.physical_tags.clone()))
            .collect(),
        None => Vec::new(),
    };
    let mut groups: Vec<i32> = of_dim.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    groups.extend(names.keys().filter(|(d, _)| *d == dim).map(|(_, t)| *t));
    groups.sort_unstable();
    groups.dedup();
    let tag = match group {
        PhysicalGroup::Tag(t) => i32::try_from(*t).ok().filter(|t| groups.contains(t)),
        PhysicalGroup::Name(n) => (names.iter())
            .find(|((d, _), name)| *d == dim && name == &n)
            .map(|((_, t), _)| *t),
    };
    let Some(tag) = tag else {
        let listed: Vec<String> = (groups.iter())
            .map(|t| match names.get(&(dim, *t)) {
                Some(n) => format!("{t} `{n}`"),
                None => t.to_string(),
            })
            .collect();
        let known = match listed.is_empty() {
            true => "it has none".to_string(),
            false => format!("its {dim}D groups are {}", listed.join(", ")),
        };
        return Err(format!(
            "no physical group {group} of dimension {dim}: {known}"
        ));
    };
    Ok(Some(
        (of_dim.iter())
            .filter(|(_, p)| p.contains(&tag))
            .map(|(e, _)| *e)
            .collect(),
    ))
}

/// The element kind of a Gmsh type, for a body of dimension `dim`; `None` for an
/// element of a lower dimension (passed over).
fn kind(t: ElementType, dim: usize, tag: u64) -> Result<Option<ElementKind>, String> {
    let kind = match t {
        ElementType::Tri3 => ElementKind::Triangle,
        ElementType::Qua4 => ElementKind::Quadrilateral,
        ElementType::Tet4 => ElementKind::Tetrahedron,
        ElementType::Hex8 => ElementKind::Hexahedron,
        _ if dim_of(t) < dim => return Ok(None),
        _ => {
            let takes = match dim {
                2 => "3-node triangles and 4-node quadrilaterals",
                _ => "4-node tetrahedra and 8-node hexahedra",
            };
            return Err(format!(
                "element {tag}: Gmsh element type {} ({t:?}) is not read: a {dim}D mesh body \
                 takes {takes}",
                t as i32
            ));
        }
    };
    Ok((kind.dim() == dim).then_some(kind))
}

/// The dimension of a Gmsh element type, from its name in mshio: points
/// (`Pnt…`) 0, lines (`Lin…`) 1, triangles, quadrilaterals and polygons 2,
/// the rest (tetrahedra, hexahedra, prisms, pyramids, polyhedra, the
/// trihedron `Trih4`) 3.
fn dim_of(t: ElementType) -> usize {
    let name = format!("{t:?}");
    let starts = |p: &[&str]| p.iter().any(|p| name.starts_with(p));
    match () {
        _ if starts(&["Pnt"]) => 0,
        _ if starts(&["Lin"]) => 1,
        _ if starts(&["Trih"]) => 3,
        _ if starts(&["Tri", "Qua", "Polyg"]) => 2,
        _ => 3,
    }
}

/// The body's elements with their nodes, numbered in the order they are first
/// used.
fn elements(
    msh: &Msh,
    entities: &Option<HashSet<i32>>,
    select: &Select,
) -> Result<ElementMesh, String> {
    let coordinates = node_coordinates(msh);
    let mut index: HashMap<u64, usize> = HashMap::new();
    let mut mesh = ElementMesh::new(select.dim, Vec::new(), Vec::new(), select.quadrature);
    let blocks = msh
        .data
        .elements
        .as_ref()
        .map_or(&[][..], |e| &e.element_blocks[..]);
    for block in blocks {
        let taken = entities
            .as_ref()
            .is_none_or(|s| s.contains(&block.entity_tag));
        if block.entity_dim as usize != select.dim || !taken {
            continue;
        }
        for e in &block.elements {
            let Some(kind) = kind(block.element_type, select.dim, e.element_tag)? else {
                continue;
            };
            let mut nodes = Vec::with_capacity(e.nodes.len());
            for &t in &e.nodes {
                let x = coordinates.get(&t).ok_or_else(|| {
                    format!(
                        "element {}: its node {t} is not in the $Nodes section",
                        e.element_tag
                    )
                })?;
                nodes.push(*index.entry(t).or_insert_with(|| {
                    mesh.nodes.push(*x);
                    mesh.nodes.len() - 1
                }));
            }
            let tag = e.element_tag;
            mesh.elements.push(Element { kind, tag, nodes });
        }
    }
    if mesh.elements.is_empty() {
        let group = select
            .physical
            .map_or(String::new(), |g| format!(" in physical group {g}"));
        return Err(format!("the file holds no {}D element{group}", select.dim));
    }
    Ok(mesh)
}

/// Node tag → coordinates, over all node blocks (module doc: dense tags).
fn node_coordinates(msh: &Msh) -> HashMap<u64, [f64; 3]> {
    let mut out = HashMap::new();
    let Some(nodes) = &msh.data.nodes else {
        return out;
    };
    let mut next = nodes.min_node_tag;
    for block in &nodes.node_blocks {
        let x = |i: usize| [block.nodes[i].x, block.nodes[i].y, block.nodes[i].z];
        match &block.node_tags {
            Some(tags) => out.extend(tags.iter().map(|(&t, &i)| (t, x(i)))),
            None => {
                for i in 0..block.nodes.len() {
                    out.insert(next, x(i));
                    next += 1;
                }
            }
        }
    }
    out
}

/// Every node of the body in the grid's [min, max] (a mesh is not cut at a
/// symmetry plane).
fn inside_grid(mesh: &ElementMesh, (min, max): (&[f64], &[f64])) -> Result<(), String> {
    for e in &mesh.elements {
        for &n in &e.nodes {
            let x = &mesh.nodes[n][..mesh.dim];
            if (0..mesh.dim).any(|d| !(x[d] >= min[d] && x[d] <= max[d])) {
                return Err(format!(
                    "element {} ({}): its node at {x:?} lies outside the grid {min:?}..{max:?}",
                    e.tag,
                    e.kind.name()
                ));
            }
        }
    }
    Ok(())
}
