//! Parameters and configurations from Python (a nested `dict`, or the path of a TOML file in
//! the command line's format) and back (a nested `dict`).
//!
//! A `dict` goes through `serde` exactly like the TOML file: unknown keys are rejected with
//! the list of known ones, omitted keys take their documented defaults, and the range checks
//! run in the facade's entry points ([`ParamError`](crate::errors::ParamError)).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Number, Value};

use crate::errors::{Error, Result};

/// A Python value (dicts, lists, tuples, strings, numbers, booleans, `None`) as JSON; `what`
/// is its dotted key path for errors.
fn to_json(x: &Bound<'_, PyAny>, what: &str) -> Result<Value> {
    if x.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = x.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if x.is_instance_of::<PyInt>() {
        if let Ok(v) = x.extract::<i64>() {
            return Ok(Value::from(v));
        }
        if let Ok(v) = x.extract::<u64>() {
            return Ok(Value::from(v));
        }
        return Err(Error::param(what, "integer out of the 64-bit range"));
    }
    if x.is_instance_of::<PyFloat>() {
        let v: f64 = x
            .extract()
            .map_err(|e: PyErr| Error::param(what, e.to_string()))?;
        return Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| Error::param(what, format!("{v} is not a finite number")));
    }
    if let Ok(s) = x.cast::<PyString>() {
        let s = s.to_cow().map_err(|e| Error::param(what, e.to_string()))?;
        return Ok(Value::String(s.into_owned()));
    }
    if let Ok(d) = x.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key: String = k
                .extract()
                .map_err(|_| Error::param(what, format!("key {k} is not a string")))?;
            let path = if what.is_empty() {
                key.clone()
            } else {
                format!("{what}.{key}")
            };
            map.insert(key, to_json(&v, &path)?);
        }
        return Ok(Value::Object(map));
    }
    if x.is_instance_of::<PyList>() || x.is_instance_of::<PyTuple>() {
        let items = x
            .try_iter()
            .map_err(|e| Error::param(what, e.to_string()))?;
        let mut out = Vec::new();
        for (k, item) in items.enumerate() {
            let item = item.map_err(|e| Error::param(what, e.to_string()))?;
            out.push(to_json(&item, &format!("{what}[{k}]"))?);
        }
        return Ok(Value::Array(out));
    }
    // NumPy scalars and anything else with __float__ (after the exact types above).
    if let Ok(v) = x.extract::<f64>() {
        return Number::from_f64(v)
            .map(Value::Number)
            .ok_or_else(|| Error::param(what, format!("{v} is not a finite number")));
    }
    let type_name = x
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    Err(Error::param(
        what,
        format!("a value of type {type_name} cannot be a parameter"),
    ))
}

/// JSON as Python objects (dicts, lists, str, int, float, bool, `None`).
pub(crate) fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u), _) => u.into_pyobject(py)?.into_any(),
            (None, None, f) => f.unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, item) in map {
                dict.set_item(k, to_py(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

/// A serializable value (parameters, study records) as Python objects.
pub(crate) fn serialize_to_py<'py, T: Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let json =
        serde_json::to_value(value).map_err(|e| Error::Panic(format!("serialization: {e}")))?;
    to_py(py, &json)
}

/// Parameters `T` from `None` (the defaults), a `dict`, or the path of a TOML file; `what`
/// names the argument in errors.
pub(crate) fn from_py<T: DeserializeOwned + Default>(
    x: Option<&Bound<'_, PyAny>>,
    what: &str,
) -> Result<T> {
    let Some(x) = x.filter(|x| !x.is_none()) else {
        return Ok(T::default());
    };
    if x.is_instance_of::<PyDict>() {
        let json = to_json(x, "")?;
        return serde_json::from_value(json).map_err(|e| Error::param(what, e.to_string()));
    }
    if let Ok(path) = x.extract::<PathBuf>() {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(&path)
            .map_err(|e| Error::param(&shown, format!("cannot read: {e}")))?;
        return toml::from_str(&text).map_err(|e| Error::param(&shown, e.to_string()));
    }
    Err(Error::param(
        what,
        "expected a dict, the path of a TOML file, or None (the defaults)",
    ))
}
