//! A scaling-relation system in the form every solver here consumes.
//!
//! Every scaling relation evaluated on a grid has the same shape (Schaefer–Warren eq. (3) and
//! section 5.2): the unknowns fall into *classes* (numerator residues mod n for uniform
//! schemes, single grid points next to an extraordinary vertex) and each class `r` is written
//! through exactly one other class, `next(r)` (the class of `2x`), or through known values only
//! (a *terminal* class: `2x` left the extraordinary patch). Each unknown `u` has one relation
//!
//! ```text
//! x_u = sum_v w_uv x_v + c_u,      every v in class next(class(u)),
//! ```
//!
//! and normalization equations (partition of unity, tangent normalization, zero-sum checks)
//! each involve the unknowns of one class. The functional graph `r -> next(r)` then splits the
//! system into independent orbits ([`crate::orbits`]).

use num_rational::BigRational;

/// A sparse linear form: `(unknown, coefficient)` pairs.
pub type SparseRow = Vec<(usize, BigRational)>;

/// The relation `x_u = sum terms + constant` of one unknown; the constant (known values, such
/// as regular basis functions next to an extraordinary vertex) is in the solver's field `S`.
#[derive(Clone, Debug, PartialEq)]
pub struct Relation<S> {
    /// Coefficients on unknowns of class `next(class(u))`.
    pub terms: SparseRow,
    /// Contribution of known values (zero for uniform schemes).
    pub constant: S,
}

/// A normalization equation `sum terms = rhs` over the unknowns of one class.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalizationRow {
    /// The class all its unknowns belong to.
    pub class: u32,
    /// The linear form.
    pub terms: SparseRow,
    /// Right-hand side.
    pub rhs: BigRational,
    /// Where it is imposed, for error messages (`"x = 1/3"`).
    pub label: String,
}

/// The whole system.
#[derive(Clone, Debug)]
pub struct ScalingSystem<S> {
    /// Class of every unknown.
    pub class_of: Vec<u32>,
    /// `next[r]`: the class that class `r`'s relations refer to; `None` for terminal classes.
    pub next: Vec<Option<u32>>,
    /// One relation per unknown.
    pub relations: Vec<Relation<S>>,
    /// The normalization equations.
    pub normalization: Vec<NormalizationRow>,
    /// A label per unknown for error messages (`"phi(4/3)"`).
    pub labels: Vec<String>,
}

impl<S> ScalingSystem<S> {
    /// An empty system over the class map `next`.
    pub fn new(next: Vec<Option<u32>>) -> Self {
        ScalingSystem {
            class_of: Vec::new(),
            next,
            relations: Vec::new(),
            normalization: Vec::new(),
            labels: Vec::new(),
        }
    }

    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.relations.len()
    }

    /// Add an unknown of `class` with its relation; its id.
    pub fn push_unknown(&mut self, class: u32, relation: Relation<S>, label: String) -> usize {
        self.class_of.push(class);
        self.relations.push(relation);
        self.labels.push(label);
        self.relations.len() - 1
    }

    /// The unknowns of every class, each in increasing order.
    pub fn unknowns_by_class(&self) -> Vec<Vec<usize>> {
        let mut classes = vec![Vec::new(); self.next.len()];
        for (u, &c) in self.class_of.iter().enumerate() {
            classes[c as usize].push(u);
        }
        classes
    }
}

/// Add `coef` to the coefficient of `u` in `row`, dropping terms that cancel.
pub fn add_to_row(row: &mut SparseRow, u: usize, coef: BigRational) {
    use num_traits::Zero;
    match row.iter_mut().position(|(v, _)| *v == u) {
        Some(i) => {
            row[i].1 += coef;
            if row[i].1.is_zero() {
                row.swap_remove(i);
            }
        }
        None if !coef.is_zero() => row.push((u, coef)),
        None => {}
    }
}
