//! Keyword options taken one by one, so that `render`, `path` and `fly` share the parsing of
//! the options they have in common (look, lens, lumen) and refuse the ones they do not know.

use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keyword options of one call, taken by name; the ones left at the end are unknown.
pub struct Kwargs<'py> {
    function: &'static str,
    left: Bound<'py, PyDict>,
}

impl<'py> Kwargs<'py> {
    /// The options given to `function` (a copy: the caller's dict is left alone).
    pub fn new(
        py: Python<'py>,
        function: &'static str,
        given: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Self> {
        let left = match given {
            Some(dict) => dict.copy()?,
            None => PyDict::new(py),
        };
        Ok(Self { function, left })
    }

    /// The option `name` converted to `T`; `None` when it is absent or `None`.
    pub fn take<T>(&self, name: &str) -> PyResult<Option<T>>
    where
        T: FromPyObjectOwned<'py>,
    {
        let Some(value) = self.left.get_item(name)? else {
            return Ok(None);
        };
        self.left.del_item(name)?;
        if value.is_none() {
            return Ok(None);
        }
        value.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            PyTypeError::new_err(format!("{}(): option {name}: {e}", self.function))
        })
    }

    /// Fails naming the options no one took.
    pub fn finish(self) -> PyResult<()> {
        if self.left.is_empty() {
            return Ok(());
        }
        let names: Vec<String> = self.left.keys().iter().map(|k| k.to_string()).collect();
        Err(PyTypeError::new_err(format!(
            "{}() got unknown option(s): {}",
            self.function,
            names.join(", ")
        )))
    }
}
