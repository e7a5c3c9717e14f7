//! The parameter table of a sweep: explicit rows or a Cartesian grid over spec paths.

use paritysim_error::{Error, Result, bail};

/// A table of parameter values: named columns, one row per point.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterTable {
    /// Column names (e.g. `drivetrain.balance_spring`).
    pub names: Vec<String>,
    /// Rows, each as long as `names`.
    pub rows: Vec<Vec<f64>>,
}

impl ParameterTable {
    /// Explicit rows.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for duplicate names; [`Error::Shape`] for a row of the wrong
    /// length.
    pub fn new(names: Vec<String>, rows: Vec<Vec<f64>>) -> Result<Self> {
        for (i, name) in names.iter().enumerate() {
            if names[..i].contains(name) {
                return Err(Error::invalid(
                    format!("parameters[{i}]"),
                    format!("{name:?}"),
                    "a name not used by another column",
                ));
            }
        }
        if let Some((i, row)) = rows
            .iter()
            .enumerate()
            .find(|(_, r)| r.len() != names.len())
        {
            bail!(Shape "row {i} has {} values but there are {} parameters", row.len(), names.len());
        }
        Ok(Self { names, rows })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// A Cartesian product of named axes (the first axis varies slowest, like
/// `itertools.product`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Grid {
    axes: Vec<(String, Vec<f64>)>,
}

impl Grid {
    /// An empty grid (one point with no parameters).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an axis.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a repeated name or an empty axis.
    pub fn axis(mut self, name: &str, values: impl IntoIterator<Item = f64>) -> Result<Self> {
        if self.axes.iter().any(|(n, _)| n == name) {
            bail!(invalid format!("grid.{name}"), "a repeated axis", "each parameter once");
        }
        let values: Vec<f64> = values.into_iter().collect();
        if values.is_empty() {
            bail!(invalid format!("grid.{name}"), "[]", "at least one value");
        }
        self.axes.push((name.to_string(), values));
        Ok(self)
    }

    /// Number of points (the product of the axis lengths).
    pub fn len(&self) -> usize {
        self.axes.iter().map(|(_, v)| v.len()).product()
    }

    /// Whether the grid has no points (never: an empty grid is one point).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of point `index` (row-major: the last axis varies fastest).
    pub fn point(&self, mut index: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.axes.len()];
        for (k, (_, values)) in self.axes.iter().enumerate().rev() {
            out[k] = values[index % values.len()];
            index /= values.len();
        }
        out
    }

    /// All points as a table.
    pub fn table(&self) -> ParameterTable {
        ParameterTable {
            names: self.axes.iter().map(|(n, _)| n.clone()).collect(),
            rows: (0..self.len()).map(|i| self.point(i)).collect(),
        }
    }
}
