//! The surface model: invariants, the matrices they build, and normal fields.
//!
//! An [`Invariant`] (6 numbers for a linear Lie algebra, 12 or 18 for a Hamiltonian one)
//! builds the matrices `A`, `B`, `C` and `H = [[A, B], [C, −Aᵀ]]` of the paper's eq. 2–4.
//! Its normal field is `v(p) = A p + B (p∘p)`: the upper block of `H ℓ(p)` with the
//! [`Lift`] `ℓ(p) = (p, p∘p)` (see DESIGN.md §1). The mesher never sees invariants, only a
//! [`NormalField`], so users can mesh fields of their own: a formula written once for every
//! scalar type ([`FieldFormula`] in a [`Formula`], which the audits can also run in every
//! precision through [`EveryScalar`]) or a closure over dual numbers ([`FnField`]).

mod field;
mod formula;
mod invariant;
mod shape;

pub(crate) use field::value_and_jacobian;
pub use field::{jacobian, FnField, Hole, LieField, NormalField};
pub use formula::{EveryScalar, FieldFormula, Formula};
pub use invariant::{AngleReading, Invariant, InvariantError, InvariantKind, Lift, Mat3};
pub(crate) use shape::bend_has_singular_point;
pub(crate) use shape::jacobian_rounding;
pub use shape::{least_aligned_tangent, LocalShape, INTEGRABLE_DEFECT};
