//! Gmsh MSH 4.1 files for the tests of mesh bodies (`shape = "mesh"`):
//! written here, ASCII or binary, from nodes and blocks of elements; a
//! rectangle of triangles or quadrilaterals and a box of hexahedra or
//! tetrahedra.

/// One block of elements: its entity's dimension and tag, the Gmsh element
/// type and the elements' node tags (element tags follow on from 1).
#[derive(Clone)]
pub struct Block {
    pub dim: usize,
    pub entity: i32,
    pub kind: u8,
    pub elements: Vec<Vec<u64>>,
}

/// An MSH 4.1 file, ASCII: nodes tagged 1.. in order, the blocks' elements
/// tagged 1.. in order, the surface (2D) or volume (3D: with a block of 3D
/// elements) entities `groups` (entity tag, its physical group tags) and the
/// named groups `names` (dimension, tag, name).
pub fn msh_ascii(
    nodes: &[[f64; 3]],
    blocks: &[Block],
    groups: &[(i32, Vec<i32>)],
    names: &[(usize, i32, &str)],
) -> String {
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
    if !names.is_empty() {
        s += &format!("$PhysicalNames\n{}\n", names.len());
        for (d, t, n) in names {
            s += &format!("{d} {t} \"{n}\"\n");
        }
        s += "$EndPhysicalNames\n";
    }
    let dim = blocks.iter().map(|b| b.dim).max().unwrap_or(2);
    let (surfaces, volumes) = if dim == 2 {
        (groups.len(), 0)
    } else {
        (0, groups.len())
    };
    s += &format!("$Entities\n0 0 {surfaces} {volumes}\n");
    for (tag, phys) in groups {
        let p: Vec<String> = phys.iter().map(|t| t.to_string()).collect();
        s += &format!("{tag} 0 0 0 1 1 1 {} {} 0\n", phys.len(), p.join(" "));
    }
    s += "$EndEntities\n";
    let n = nodes.len();
    s += &format!("$Nodes\n1 {n} 1 {n}\n{dim} 1 0 {n}\n");
    (1..=n).for_each(|t| s += &format!("{t}\n"));
    for x in nodes {
        s += &format!("{:?} {:?} {:?}\n", x[0], x[1], x[2]);
    }
    s += "$EndNodes\n";
    let total: usize = blocks.iter().map(|b| b.elements.len()).sum();
    s += &format!("$Elements\n{} {total} 1 {total}\n", blocks.len());
    let mut tag = 1;
    for b in blocks {
        s += &format!("{} {} {} {}\n", b.dim, b.entity, b.kind, b.elements.len());
        for e in &b.elements {
            let nodes: Vec<String> = e.iter().map(|t| t.to_string()).collect();
            s += &format!("{tag} {}\n", nodes.join(" "));
            tag += 1;
        }
    }
    s + "$EndElements\n"
}

/// The same file in binary (little-endian, 8-byte size_t).
pub fn msh_binary(nodes: &[[f64; 3]], blocks: &[Block], groups: &[(i32, Vec<i32>)]) -> Vec<u8> {
    let size = |v: &mut Vec<u8>, x: usize| v.extend((x as u64).to_le_bytes());
    let int = |v: &mut Vec<u8>, x: i32| v.extend(x.to_le_bytes());
    let mut s = b"$MeshFormat\n4.1 1 8\n".to_vec();
    int(&mut s, 1);
    s.extend(b"\n$EndMeshFormat\n$Entities\n");
    let dim = blocks.iter().map(|b| b.dim).max().unwrap_or(2);
    let counts = if dim == 2 {
        [0, 0, groups.len(), 0]
    } else {
        [0, 0, 0, groups.len()]
    };
    counts.iter().for_each(|&c| size(&mut s, c));
    for (tag, phys) in groups {
        int(&mut s, *tag);
        [0.0f64, 0.0, 0.0, 1.0, 1.0, 1.0]
            .iter()
            .for_each(|x| s.extend(x.to_le_bytes()));
        size(&mut s, phys.len());
        phys.iter().for_each(|&p| int(&mut s, p));
        size(&mut s, 0);
    }
    s.extend(b"\n$EndEntities\n$Nodes\n");
    let n = nodes.len();
    [1, n, 1, n].iter().for_each(|&c| size(&mut s, c));
    [dim as i32, 1, 0].iter().for_each(|&c| int(&mut s, c));
    size(&mut s, n);
    (1..=n).for_each(|t| size(&mut s, t));
    nodes
        .iter()
        .flatten()
        .for_each(|x| s.extend(x.to_le_bytes()));
    s.extend(b"\n$EndNodes\n$Elements\n");
    let total: usize = blocks.iter().map(|b| b.elements.len()).sum();
    [blocks.len(), total, 1, total]
        .iter()
        .for_each(|&c| size(&mut s, c));
    let mut tag = 1;
    for b in blocks {
        [b.dim as i32, b.entity, i32::from(b.kind)]
            .iter()
            .for_each(|&c| int(&mut s, c));
        size(&mut s, b.elements.len());
        for e in &b.elements {
            size(&mut s, tag);
            e.iter().for_each(|&t| size(&mut s, t as usize));
            tag += 1;
        }
    }
    s.extend(b"\n$EndElements\n");
    s
}

/// The rectangle [x0, x1] × [y0, y1] as nx × ny quadrilaterals (Gmsh type 3)
/// or each cut into two triangles (type 2), counter-clockwise; nodes tagged
/// from 1 row by row.
pub fn rectangle(
    x: [f64; 2],
    y: [f64; 2],
    n: [usize; 2],
    triangles: bool,
) -> (Vec<[f64; 3]>, Vec<Vec<u64>>) {
    let mut nodes = Vec::new();
    for j in 0..=n[1] {
        for i in 0..=n[0] {
            let s = [i as f64 / n[0] as f64, j as f64 / n[1] as f64];
            nodes.push([
                x[0] + s[0] * (x[1] - x[0]),
                y[0] + s[1] * (y[1] - y[0]),
                0.0,
            ]);
        }
    }
    let tag = |i: usize, j: usize| (1 + j * (n[0] + 1) + i) as u64;
    let mut elements = Vec::new();
    for j in 0..n[1] {
        for i in 0..n[0] {
            let (a, b, c, d) = (tag(i, j), tag(i + 1, j), tag(i + 1, j + 1), tag(i, j + 1));
            match triangles {
                true => elements.extend([vec![a, b, c], vec![a, c, d]]),
                false => elements.push(vec![a, b, c, d]),
            }
        }
    }
    (nodes, elements)
}

/// The box [min, max] as n[0] × n[1] × n[2] hexahedra (Gmsh type 5), or each
/// cut into 6 tetrahedra about its diagonal from corner 0 to corner 6 (type 4),
/// all of positive volume; nodes tagged from 1, x fastest.
pub fn box_mesh(
    min: [f64; 3],
    max: [f64; 3],
    n: [usize; 3],
    tetrahedra: bool,
) -> (Vec<[f64; 3]>, Vec<Vec<u64>>) {
    let mut nodes = Vec::new();
    for k in 0..=n[2] {
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let s = [i, j, k];
                nodes.push(std::array::from_fn(|d| {
                    min[d] + s[d] as f64 / n[d] as f64 * (max[d] - min[d])
                }));
            }
        }
    }
    let tag = |i: usize, j: usize, k: usize| (1 + (k * (n[1] + 1) + j) * (n[0] + 1) + i) as u64;
    let mut elements = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let c = [
                    tag(i, j, k),
                    tag(i + 1, j, k),
                    tag(i + 1, j + 1, k),
                    tag(i, j + 1, k),
                    tag(i, j, k + 1),
                    tag(i + 1, j, k + 1),
                    tag(i + 1, j + 1, k + 1),
                    tag(i, j + 1, k + 1),
                ];
                match tetrahedra {
                    false => elements.push(c.to_vec()),
                    true => elements.extend(
                        [
                            [0, 1, 2, 6],
                            [0, 2, 3, 6],
                            [0, 3, 7, 6],
                            [0, 7, 4, 6],
                            [0, 4, 5, 6],
                            [0, 5, 1, 6],
                        ]
                        .map(|t| t.map(|a| c[a]).to_vec()),
                    ),
                }
            }
        }
    }
    (nodes, elements)
}
