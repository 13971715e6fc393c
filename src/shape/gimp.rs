//! GIMP (placeholder, replaced on the shape branch).
use crate::dim::Vector;
use crate::grid::Grid;
pub fn evaluate<const D: usize>(_grid: &Grid<D>, _x: &Vector<D>, _half: &Vector<D>, _node: &mut [u32], _w: &mut [f64], _grad: &mut [Vector<D>]) -> usize { todo!("shape::gimp") }
