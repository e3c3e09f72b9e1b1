//! Parameters stored by name after the payload: how a library parameter added after the
//! format was fixed is stored without a new format version (module docs of [`super`],
//! "Adding a library parameter").
//!
//! Each such parameter has a name (its path in the parameters, e.g. `fit.warp.rate_form`) and
//! an *absent value*: the value that reproduces what builds before the parameter did (usually
//! its default; for a parameter whose default changes behaviour, the old behaviour). A
//! parameter at its absent value is not written at all, so a planner that does not use the
//! new parameter saves exactly the bytes it saved before the parameter existed; one that
//! does use it gets an entry (name, postcard bytes of the value) in a list written after the
//! payload. Reading takes each known name out of the list (absent: the absent value); a name
//! left over was written by a newer build and is refused ([`Extras::finish`]), never ignored.
//! A build from before this list (or one that does not know an entry) refuses such a file
//! as a whole (its payload has undecoded bytes), so a parameter is never silently dropped.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Parameters stored by name after the payload (module docs): `(name, postcard bytes of the
/// value)` in the order they were put.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Extras {
    entries: Vec<(String, Vec<u8>)>,
}

impl Extras {
    /// Stores `value` under `name` unless it equals `absent` (then nothing is written: the
    /// bytes are those of a build without the parameter).
    ///
    /// # Errors
    /// [`Error::Encode`] if the value cannot be encoded.
    pub fn put<T: Serialize + PartialEq>(
        &mut self,
        name: &str,
        value: &T,
        absent: &T,
    ) -> Result<()> {
        if value == absent {
            return Ok(());
        }
        let bytes = postcard::to_allocvec(value).map_err(|source| Error::Encode { source })?;
        self.entries.push((name.to_owned(), bytes));
        Ok(())
    }

    /// Takes the value stored under `name` out of the list; `absent` when there is none.
    ///
    /// # Errors
    /// [`Error::Inconsistent`] when the stored bytes are not a value of type `T`.
    pub fn take<T: DeserializeOwned>(&mut self, name: &str, absent: T) -> Result<T> {
        let Some(i) = self.entries.iter().position(|(n, _)| n == name) else {
            return Ok(absent);
        };
        let (_, bytes) = self.entries.remove(i);
        let (value, rest) =
            postcard::take_from_bytes::<T>(&bytes).map_err(|e| Error::Inconsistent {
                what: "parameters stored by name",
                why: format!("`{name}` does not decode: {e}"),
            })?;
        if !rest.is_empty() {
            return Err(Error::Inconsistent {
                what: "parameters stored by name",
                why: format!("`{name}` has {} undecoded bytes", rest.len()),
            });
        }
        Ok(value)
    }

    /// No parameter stored by name.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The stored names, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.entries.iter().map(|(n, _)| n.as_str())
    }

    /// Ends reading: every stored name must have been taken.
    ///
    /// # Errors
    /// [`Error::Inconsistent`] naming the parameters this build does not know.
    pub fn finish(self) -> Result<()> {
        if self.entries.is_empty() {
            return Ok(());
        }
        let names: Vec<&str> = self.names().collect();
        Err(Error::Inconsistent {
            what: "parameters stored by name",
            why: format!(
                "this build does not know {}: the file was written by a newer build; use that \
                 build",
                names.join(", ")
            ),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_at_its_absent_value_is_not_written_and_reads_back_as_it() {
        let mut x = Extras::default();
        x.put("a", &3u32, &3u32).unwrap();
        assert!(x.is_empty());
        x.put("b", &2.5f64, &0.0).unwrap();
        assert_eq!(x.names().collect::<Vec<_>>(), ["b"]);
        assert_eq!(x.take("a", 3u32).unwrap(), 3);
        assert_eq!(x.take("b", 0.0f64).unwrap(), 2.5);
        x.finish().unwrap();
    }

    #[test]
    fn an_unknown_name_is_refused_naming_it() {
        let mut x = Extras::default();
        x.put("fit.warp.rate_form", &1u8, &0u8).unwrap();
        let err = x.finish().unwrap_err().to_string();
        assert!(
            err.contains("fit.warp.rate_form") && err.contains("newer build"),
            "{err}"
        );
    }

    #[test]
    fn a_value_of_another_type_is_refused() {
        let mut x = Extras::default();
        x.put("n", &vec![1.0f64, 2.0], &Vec::new()).unwrap();
        // Three bytes of a length-2 list of f64 are not a u8 alone.
        let err = x.take::<u8>("n", 0).unwrap_err().to_string();
        assert!(err.contains("`n`"), "{err}");
    }
}
