//! Tests of the multigrid algebra: the sparse formats, the Galerkin products
//! over the lower triangle, the V-cycle with a singular coarse level.

use super::lower::COLUMNS_PER_TASK;
use super::*;
use crate::solver::linear::iterative::Preconditioner;
use crate::solver::linear::node_pattern::NodeLists;
use crate::solver::linear::Index;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use std::sync::Arc;

/// The 1D Laplacian tridiag(−1, 2, −1) of order n as CSR.
fn laplacian(n: usize) -> Csr {
    let mut m = Csr {
        rows: n,
        cols: n,
        row_ptr: vec![0],
        ..Default::default()
    };
    for i in 0..n {
        if i > 0 {
            m.col.push(i as u32 - 1);
            m.val.push(-1.0);
        }
        m.col.push(i as u32);
        m.val.push(2.0);
        if i + 1 < n {
            m.col.push(i as u32 + 1);
            m.val.push(-1.0);
        }
        m.row_ptr.push(m.col.len());
    }
    m
}

#[test]
fn galerkin_of_the_identity_prolongation_is_the_operator() {
    let a = laplacian(7);
    let p = Csr {
        rows: 7,
        cols: 7,
        row_ptr: (0..=7).collect(),
        col: (0..7).collect(),
        val: vec![1.0; 7],
    };
    let c = galerkin(&p.transpose(), &a, &p);
    assert_eq!(c.row_ptr, a.row_ptr);
    assert_eq!(c.col, a.col);
    assert_eq!(c.val, a.val);
}

#[test]
fn transpose_twice_is_the_matrix() {
    let mut a = laplacian(5);
    a.val[1] = 3.0;
    let t = a.transpose();
    assert_eq!(t.val[2], 3.0);
    let tt = t.transpose();
    assert_eq!((tt.row_ptr, tt.col, tt.val), (a.row_ptr, a.col, a.val));
}

#[test]
fn compressed_columns_read_as_rows_are_the_matrix() {
    // P's arrays read as compressed columns are Pᵀ; entry by entry
    // against P itself.
    let p = interpolation(23, false);
    let col_ptr: Vec<Index> = p.row_ptr.iter().map(|&k| k as Index).collect();
    let pattern = SymbolicSparseColMat::new_checked(p.cols, p.rows, col_ptr, None, p.col.clone());
    let t = Csr::from_csc(SparseColMatRef::new(pattern.as_ref(), &p.val));
    assert_eq!((t.rows, t.cols), (p.cols, p.rows));
    for i in 0..p.rows {
        let (c, v) = p.row(i);
        for (&j, &a) in c.iter().zip(v) {
            let (tc, tv) = t.row(j as usize);
            assert_eq!(
                tc.binary_search(&(i as u32)).map(|k| tv[k]),
                Ok(a),
                "({i}, {j})"
            );
        }
    }
    assert_eq!(t.nnz(), p.nnz());
}

/// Linear interpolation from coarse node i (at fine node 2i + 1) to the
/// fine nodes of a 1D grid of `n` = 2 n_c + 1 unknowns, with column
/// `n_c − 1` given twice when `duplicate` (columns n_c − 1 and n_c equal).
fn interpolation(n: usize, duplicate: bool) -> Csr {
    let nc = (n - 1) / 2;
    let mut p = Csr {
        rows: n,
        cols: nc + usize::from(duplicate),
        row_ptr: vec![0],
        ..Default::default()
    };
    for i in 0..n {
        let mut entries: Vec<(usize, f64)> = match i % 2 {
            1 => vec![(i / 2, 1.0)],
            _ => vec![(i / 2, 0.5), ((i / 2).wrapping_sub(1), 0.5)],
        };
        // An even n leaves the last unknown without a coarse parent.
        entries.retain(|&(c, _)| c < nc);
        if duplicate {
            if let Some(&(_, w)) = entries.iter().find(|e| e.0 == nc - 1) {
                entries.push((nc, w));
            }
        }
        entries.sort_by_key(|e| e.0);
        for (c, w) in entries {
            p.col.push(c as u32);
            p.val.push(w);
        }
        p.row_ptr.push(p.col.len());
    }
    p
}

/// A symmetric matrix whose unknowns come in nodes (node a owns
/// `first[a]..first[a + 1]`, and nodes a, b couple all their unknowns when
/// `coupled(max(a, b), min(a, b))`): its lower triangle in compressed
/// columns with the node graph, and the whole matrix in compressed rows
/// built directly from the same rule (the reference).
struct Nodal {
    col_ptr: Arc<[Index]>,
    /// The triangle's rows, written out by the rule (the reference).
    rows: Vec<Index>,
    vals: Vec<f64>,
    whole: Csr,
    lists: Arc<NodeLists>,
}

impl Nodal {
    fn new(first: Vec<usize>, coupled: impl Fn(usize, usize) -> bool) -> Nodal {
        let nodes = first.len() - 1;
        let n = first[nodes];
        let node_of = |i: usize| first.partition_point(|&u| u <= i) - 1;
        let entry = |i: usize, j: usize| {
            let (a, b) = (node_of(i), node_of(j));
            coupled(a.max(b), a.min(b)).then(|| match i == j {
                true => 4.0 + j as f64,
                false => -1.0 / (1 + i + j) as f64,
            })
        };
        let (mut col_ptr, mut rows, mut vals) = (vec![0 as Index], Vec::new(), Vec::new());
        for j in 0..n {
            for (i, v) in (j..n).filter_map(|i| entry(i, j).map(|v| (i, v))) {
                rows.push(i as Index);
                vals.push(v);
            }
            col_ptr.push(rows.len() as Index);
        }
        let mut whole = Csr {
            rows: n,
            cols: n,
            row_ptr: vec![0],
            ..Default::default()
        };
        for i in 0..n {
            for (j, v) in (0..n).filter_map(|j| entry(i, j).map(|v| (j, v))) {
                whole.col.push(j as u32);
                whole.val.push(v);
            }
            whole.row_ptr.push(whole.col.len());
        }
        let (mut start, mut adjacency) = (vec![0], Vec::new());
        for a in 0..nodes {
            adjacency.extend(
                (0..nodes)
                    .filter(|&b| coupled(a.max(b), a.min(b)))
                    .map(|b| b as u32),
            );
            start.push(adjacency.len());
        }
        Nodal {
            col_ptr: col_ptr.into(),
            rows,
            vals,
            whole,
            lists: Arc::new(NodeLists {
                start,
                adjacency,
                first,
            }),
        }
    }

    fn fine(&self) -> Fine {
        Fine::Lower(
            Arc::clone(&self.col_ptr),
            self.vals.clone(),
            Arc::clone(&self.lists),
        )
    }
}

/// A ragged pattern of order n, one unknown per node (some columns hold
/// only their diagonal, some rows reach far).
fn ragged(n: usize) -> Nodal {
    Nodal::new((0..=n).collect(), |i, j| {
        let coupled = i == j || (i - j < 10 && (i - j) % 3 == 1) || (j % 5 == 0 && i == n - 1);
        coupled && !(j % 7 == 3 && i > j)
    })
}

/// Nodes of 2 unknowns, some of 1 or none (eliminated components), each
/// coupled to the nodes two either side of it and the first to the last.
fn nodal(nodes: usize) -> Nodal {
    let mut first = vec![0];
    for a in 0..nodes {
        let own = match (a % 5, a % 7) {
            (_, 4) => 0,
            (2, _) => 1,
            _ => 2,
        };
        first.push(first[a] + own);
    }
    Nodal::new(first, |a, b| a - b <= 2 || (b == 0 && a == nodes - 1))
}

#[test]
fn the_lower_triangle_read_by_rows_is_the_whole_matrix() {
    // Row for row, the same columns, values and order as the copy into
    // compressed rows, so the Galerkin operators are the same bits: on a
    // ragged pattern of single unknowns, and on nodes of 2, 1 and 0
    // unknowns.
    for (case, m) in [("ragged", ragged(23)), ("nodal", nodal(20))] {
        let lower = Operator::fine(m.fine()).unwrap();
        let (rows, n) = (&m.whole, m.whole.rows);
        assert_eq!(lower.nnz(), rows.nnz(), "{case}");
        let Operator::Lower(a) = &lower else {
            panic!("a symmetric tangent is read in place")
        };
        // The rows that the node graph gives are those of the rule.
        let (pattern, values) = a.to_csc();
        assert_eq!(
            (pattern.row_idx(), &values),
            (&m.rows[..], &m.vals),
            "{case}"
        );
        let by_rows = LowerRows::new(a).unwrap();
        for i in 0..n {
            let mut entries = Vec::new();
            by_rows.for_each_in_row(i, |j, v| entries.push((j, v)));
            let (c, v) = rows.row(i);
            let expected: Vec<(u32, f64)> = c.iter().copied().zip(v.iter().copied()).collect();
            assert_eq!(entries, expected, "{case}: row {i}");
        }
        for block in [vec![0, 1], vec![3, 4, 5], vec![n - 1, 9, 1], vec![7]] {
            assert_eq!(
                lower.block_values(&block),
                rows.block_values(&block),
                "{case}"
            );
        }
        let p = interpolation(n, false);
        let (a, b) = (
            lower.galerkin(&p.transpose(), &p).unwrap(),
            galerkin(&p.transpose(), rows, &p),
        );
        assert_eq!(
            (a.row_ptr, a.col, a.val),
            (b.row_ptr, b.col, b.val),
            "{case}"
        );
        // A V-cycle differs from the one on the copy only by the order of
        // the products' sums.
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let blocks: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
        let cycle = |fine: Fine| {
            let transfer = Transfer {
                prolongation: p.clone(),
                fine_blocks: blocks.clone(),
            };
            let mut mg = Multigrid::new(vec![transfer]);
            mg.refresh(fine, true).unwrap();
            let mut z = vec![0.0; n];
            mg.apply(&x, &mut z);
            z
        };
        let (z, z_rows) = (cycle(m.fine()), cycle(Fine::Rows(rows.clone())));
        let scale = z_rows.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (a, b) in z.iter().zip(&z_rows) {
            assert!(
                (a - b).abs() <= 1e-13 * scale,
                "{case}: V-cycle {a} against {b}"
            );
        }
    }
}

#[test]
fn a_symmetric_coarse_level_keeps_its_lower_triangle() {
    // A Galerkin operator of the ragged symmetric matrix (a coarse level),
    // kept as its lower triangle: half the stored entries, the same
    // products (to the order of the sums), blocks and coarse
    // factorization input.
    let m = ragged(2 * COLUMNS_PER_TASK + 77);
    let p = interpolation(m.whole.rows, false);
    let coarse = galerkin(&p.transpose(), &m.whole, &p);
    let n = coarse.rows;
    let mut lower = Operator::Rows(coarse.clone());
    lower.keep_lower_triangle();
    let Operator::Lower(l) = &lower else {
        panic!("kept as a lower triangle")
    };
    let diagonal = (0..n)
        .filter(|&i| coarse.row(i).0.contains(&(i as u32)))
        .count();
    assert_eq!(l.values.len(), (coarse.nnz() + diagonal) / 2);
    assert_eq!(lower.nnz(), coarse.nnz());
    let x: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
    let (mut y, mut expected) = (vec![0.0; n], vec![0.0; n]);
    lower.apply(&x, &mut y);
    coarse.apply(&x, &mut expected);
    let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in y.iter().zip(&expected) {
        assert!((a - b).abs() <= 1e-13 * scale, "{a} against {b}");
    }
    for block in [vec![0, 1], vec![3, 4, 5], vec![n - 1, 9, 1]] {
        let (a, b) = (lower.block_values(&block), coarse.block_values(&block));
        // The lower triangle's block is exactly symmetric, from the upper entries.
        for (i, row) in block.iter().enumerate() {
            for (j, col) in block.iter().enumerate() {
                let upper = &b[block.len() * i.min(j) + j.max(i)];
                assert_eq!(a[block.len() * i + j], *upper, "({row}, {col})");
            }
        }
    }
    let ((pa, va), (pb, vb)) = (lower.to_csc(true), Operator::Rows(coarse).to_csc(true));
    assert_eq!(
        (pa.col_ptr(), pa.row_idx(), va),
        (pb.col_ptr(), pb.row_idx(), vb)
    );
}

#[test]
fn a_node_graph_that_misses_entries_of_the_triangle_is_refused() {
    // The graph of another pattern (node 0 no longer coupled to the last):
    // its rows would silently lack entries.
    let m = nodal(20);
    let other = Nodal::new(m.lists.first.clone(), |a, b| a - b <= 2);
    let wrong = || {
        Fine::Lower(
            Arc::clone(&m.col_ptr),
            m.vals.clone(),
            Arc::clone(&other.lists),
        )
    };
    let error = Operator::fine(wrong()).unwrap_err();
    assert!(
        error.contains("does not describe the tangent's pattern"),
        "{error}"
    );
    let p = interpolation(m.whole.rows, false);
    let mut mg = Multigrid::new(vec![Transfer {
        prolongation: p,
        fine_blocks: (0..m.whole.rows).map(|i| vec![i]).collect(),
    }]);
    assert!(mg.refresh(wrong(), true).is_err());
}

#[test]
fn products_over_the_lower_triangle_are_the_whole_matrix_on_any_thread_count() {
    // Several column chunks, columns that reach the last row from far
    // above, and columns holding only their diagonal.
    for n in [1, 7, COLUMNS_PER_TASK + 1, 2 * COLUMNS_PER_TASK + 77] {
        let m = ragged(n);
        let lower = Operator::fine(m.fine()).unwrap();
        let x: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
        let mut expected = vec![0.0; n];
        m.whole.apply(&x, &mut expected);
        let product = |threads: usize| {
            let mut y = vec![f64::NAN; n];
            crate::parallel::on_threads(threads, || lower.apply(&x, &mut y));
            y
        };
        let (one, two) = (product(1), product(2));
        assert_eq!(one, two, "n = {n}: the bits depend on the threads");
        for (i, (a, b)) in one.iter().zip(&expected).enumerate() {
            assert!(
                (a - b).abs() <= 1e-14 * b.abs().max(1.0),
                "n = {n}, row {i}: {a} against {b}"
            );
        }
    }
}

#[test]
fn a_singular_coarse_operator_is_shifted_not_replaced_by_the_fine_one() {
    // Two coinciding coarse basis functions (P z = 0) make A_c = Pᵀ A P
    // singular. The hierarchy keeps its coarse level, factorized with the
    // shift, and the V-cycle is the one without the duplicate (the
    // restricted residual has no component along z, P x_c none either).
    let n = 31;
    let a = laplacian(n);
    let blocks: Vec<Vec<usize>> = (0..n).map(|i| vec![i]).collect();
    let cycle = |duplicate: bool| {
        let transfer = Transfer {
            prolongation: interpolation(n, duplicate),
            fine_blocks: blocks.clone(),
        };
        let mut mg = Multigrid::new(vec![transfer]);
        let shape = mg.refresh(a.clone(), true).unwrap();
        let r: Vec<f64> = (0..n).map(|i| ((i * 7 % 11) as f64 - 5.0) / 3.0).collect();
        let mut z = vec![0.0; n];
        mg.apply(&r, &mut z);
        (shape, mg.depth(), z)
    };
    let (plain, depth, z) = cycle(false);
    assert_eq!(
        (plain.coarse_shift, depth, plain.unknowns.clone()),
        (0.0, 2, vec![31, 15])
    );
    let (shifted, depth, z_dup) = cycle(true);
    assert_eq!(
        (shifted.coarse_shift, depth, shifted.unknowns),
        (COARSE_SHIFT, 2, vec![31, 16])
    );
    let scale = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = z
        .iter()
        .zip(&z_dup)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        diff < 1e-6 * scale,
        "V-cycles differ by {diff:.2e} of {scale:.2e}"
    );
}
