//! Shared values written once: the serde form of an `Arc<T>` that several parts of a history
//! state point to (a stored turning state in the memory, the recall traces and the phase's
//! base; an earlier stick zone in the chains of many later ones).
//!
//! Inside [`write_shared`] and [`read_shared`] an `Arc` is written as `{"id": n, "value": …}`
//! the first time it is met and as `{"id": n}` after that, and read back as one `Arc` again, so
//! a state written and read keeps its sharing (and its size: the chains of a long history
//! would otherwise be written once per reference). Outside them every `Arc` is written whole
//! (`"id"` absent), as serde's own `Arc` support does. Fields opt in with
//! `#[serde(with = "crate::shared")]` (or `crate::shared::option` for an `Option<Arc<T>>`).

use std::any::TypeId;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Arc;
use std::thread::LocalKey;

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

// While writing: the id of each `Arc` met, by type and address; while reading: each `Arc`
// read, by id (`crate::cache`).
use crate::cache::{SERDE_READ as READ, SERDE_WRITTEN as WRITTEN};

/// Run `write` (a serialisation) with shared `Arc`s written once; inside another
/// `write_shared`, as part of the outer one (its values are shared with the outer's).
pub fn write_shared<R>(write: impl FnOnce() -> R) -> R {
    in_scope(&WRITTEN, write)
}

/// Run `read` (a deserialisation) of what [`write_shared`] wrote; inside another
/// `read_shared`, as part of the outer one.
pub fn read_shared<R>(read: impl FnOnce() -> R) -> R {
    in_scope(&READ, read)
}

/// Run `f` with the table `key` open: a new empty table unless one is open already (then `f`
/// is part of the outer scope). The table is closed when the outermost scope ends, also when
/// `f` unwinds.
fn in_scope<K: 'static, V: 'static, R>(
    key: &'static LocalKey<RefCell<Option<HashMap<K, V>>>>,
    f: impl FnOnce() -> R,
) -> R {
    if key.with(|t| t.borrow().is_some()) {
        return f();
    }
    key.with(|t| *t.borrow_mut() = Some(HashMap::new()));
    struct Scope<K: 'static, V: 'static>(&'static LocalKey<RefCell<Option<HashMap<K, V>>>>);
    impl<K: 'static, V: 'static> Drop for Scope<K, V> {
        fn drop(&mut self) {
            self.0.with(|t| *t.borrow_mut() = None);
        }
    }
    let _scope = Scope(key);
    f()
}

#[derive(Serialize)]
struct Out<'a, T> {
    #[serde(skip_serializing_if = "Option::is_none")]
    id: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    value: Option<&'a T>,
}

#[derive(Deserialize)]
struct In<T> {
    id: Option<u64>,
    value: Option<T>,
}

/// Write an `Arc<T>` (see the module docs).
pub fn serialize<S: Serializer, T: Serialize + 'static>(
    arc: &Arc<T>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    let key = (TypeId::of::<T>(), Arc::as_ptr(arc) as usize);
    let seen = WRITTEN.with(|w| {
        w.borrow_mut().as_mut().map(|ids| {
            let next = ids.len() as u64;
            match ids.get(&key) {
                Some(&id) => (id, true),
                None => {
                    ids.insert(key, next);
                    (next, false)
                }
            }
        })
    });
    let out = match seen {
        None => Out {
            id: None,
            value: Some(arc.as_ref()),
        },
        Some((id, true)) => Out {
            id: Some(id),
            value: None,
        },
        Some((id, false)) => Out {
            id: Some(id),
            value: Some(arc.as_ref()),
        },
    };
    out.serialize(serializer)
}

/// Read an `Arc<T>` (see the module docs).
pub fn deserialize<'de, D: Deserializer<'de>, T: Deserialize<'de> + 'static>(
    deserializer: D,
) -> Result<Arc<T>, D::Error> {
    let In { id, value } = In::<T>::deserialize(deserializer)?;
    match (id, value) {
        (id, Some(value)) => {
            let arc = Arc::new(value);
            if let Some(id) = id {
                READ.with(|r| {
                    if let Some(read) = r.borrow_mut().as_mut() {
                        read.insert(id, Box::new(arc.clone()));
                    }
                });
            }
            Ok(arc)
        }
        (Some(id), None) => READ
            .with(|r| {
                r.borrow()
                    .as_ref()
                    .and_then(|read| read.get(&id))
                    .and_then(|any| any.downcast_ref::<Arc<T>>())
                    .cloned()
            })
            .ok_or_else(|| D::Error::custom(format!("shared value {id} is not defined before"))),
        (None, None) => Err(D::Error::custom("a shared value needs an id or a value")),
    }
}

/// The same for an `Option<Arc<T>>`.
pub mod option {
    use super::*;

    #[derive(Serialize)]
    struct Wrap<'a, T: Serialize + 'static>(
        #[serde(serialize_with = "super::serialize")] &'a Arc<T>,
    );

    #[derive(Deserialize)]
    struct Unwrap<T>(#[serde(deserialize_with = "super::deserialize")] Arc<T>)
    where
        T: for<'a> Deserialize<'a> + 'static;

    /// Write an `Option<Arc<T>>`.
    pub fn serialize<S: Serializer, T: Serialize + 'static>(
        arc: &Option<Arc<T>>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        arc.as_ref().map(Wrap).serialize(serializer)
    }

    /// Read an `Option<Arc<T>>`.
    pub fn deserialize<'de, D: Deserializer<'de>, T: for<'a> Deserialize<'a> + 'static>(
        deserializer: D,
    ) -> Result<Option<Arc<T>>, D::Error> {
        Ok(Option::<Unwrap<T>>::deserialize(deserializer)?.map(|u| u.0))
    }
}

/// `f64` values that may be infinite (the memory's outer pieces): finite values as numbers,
/// ±∞ as the strings `"inf"` and `"-inf"` (JSON has no infinity).
pub mod extended {
    use super::*;

    #[derive(Serialize, Deserialize)]
    #[serde(untagged)]
    enum Repr {
        Number(f64),
        Text(String),
    }

    /// Write an `f64`.
    pub fn serialize<S: Serializer>(x: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            serializer.serialize_f64(*x)
        } else if x.is_nan() {
            serializer.serialize_str("nan")
        } else if *x > 0.0 {
            serializer.serialize_str("inf")
        } else {
            serializer.serialize_str("-inf")
        }
    }

    /// Read an `f64`.
    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        match Repr::deserialize(deserializer)? {
            Repr::Number(x) => Ok(x),
            Repr::Text(t) => match t.as_str() {
                "inf" => Ok(f64::INFINITY),
                "-inf" => Ok(f64::NEG_INFINITY),
                "nan" => Ok(f64::NAN),
                other => Err(D::Error::custom(format!("`{other}` is not a number"))),
            },
        }
    }
}

/// Give the memory this thread's allocator keeps for reuse back to the system, where the
/// allocator is the command's (mimalloc, feature `mimalloc`): for a worker thread about to
/// end, whose pages mimalloc would otherwise leave to be reclaimed by other threads later (on
/// the default contact's steady cycles, a check thread per stretch without this: 125 MB peak
/// over 10,000 cycles).
pub(crate) fn release_thread_memory() {
    #[cfg(feature = "mimalloc")]
    // SAFETY: `mi_collect` only returns this thread's free pages to the system; it is sound
    // to call from any thread at any time.
    unsafe {
        libmimalloc_sys::mi_collect(true)
    };
}
