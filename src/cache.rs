//! The crate's only statics: the process-wide tables keyed by size, each thread's scratch
//! buffers, and the scopes of the serde form of shared values. Nothing here carries
//! information from one load step to the next: a table is a pure function of its key, and a
//! scratch buffer is overwritten before it is read. (What does carry information between
//! steps to go faster is switched by [`crate::contact::tangential::Accelerations`].)
//!
//! # Tables keyed by size
//! Built on first use and kept for the process: a run uses a handful of sizes, a few hundred
//! kilobytes in all. A table built once is, bit for bit, the table built afresh (the same
//! operations on the same key), so the cache changes no result.
//!
//! - [`graded_rule`]: the n-point sine-graded Gauss–Legendre rule on [−1, 1]
//!   (`u = sin(πv/2)`) with its cumulative matrix (the contact integrals, the dissipation,
//!   the fade integrals; `contact::rules`).
//! - [`plain_rule`]: the n-point Gauss–Legendre rule with its cumulative matrix (the smooth
//!   pieces of those integrals).
//! - [`chebyshev_points`]: the N Chebyshev points `cos((2k+1)π/(2N))` and the planned fast
//!   cosine transform of a stick zone's piecewise tables (`contact::stick_zone`).
//!
//! The tables live in one list per kind under a lock. Each thread also keeps the entries it
//! has used: the two threads of a history (steps and their increments) look tables up
//! thousands of times per run, and contended locks of the shared list cost 3 % of the
//! default run in futex calls.
//!
//! # Scratch of one thread
//! Buffers a hot loop would otherwise allocate at every call; each call sizes and writes
//! what it reads, so their contents never reach a result:
//! - [`with_transform_work`]: the real and complex buffers of the fast cosine and sine
//!   transforms ([`crate::transforms`]), grown to the largest size used.
//! - [`with_column_sums`]: the padded sums of a column matrix's products
//!   ([`crate::quadrature::ColumnMatrix`]), at every pass of the tangential solver's inner
//!   iteration.
//!
//! # Scopes of the serde form
//! [`SERDE_WRITTEN`] and [`SERDE_READ`] hold the identities of the shared values met while one
//! state is written or read (`crate::shared`); they are empty outside those calls.

use std::any::{Any, TypeId};
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::Mutex;
use std::thread::LocalKey;

use crate::contact::rules::GradedRule;
use crate::contact::stick_zone::ChebyshevPoints;
use crate::transforms::Work;

/// Tables of one kind built once per size for the process: `(size, table)`.
type SizeTables<T> = Mutex<Vec<(usize, &'static T)>>;

/// A thread's copy of the entries of a [`SizeTables`] it has used.
type KnownSizes<T> = RefCell<Vec<(usize, &'static T)>>;

/// The sine-graded Gauss–Legendre rule with `nodes` points and its cumulative matrix.
pub(crate) fn graded_rule(nodes: usize) -> &'static GradedRule {
    static RULES: SizeTables<GradedRule> = Mutex::new(Vec::new());
    thread_local! {
        static KNOWN: KnownSizes<GradedRule> = const { RefCell::new(Vec::new()) };
    }
    built_once(&RULES, &KNOWN, nodes, GradedRule::new)
}

/// The plain Gauss–Legendre rule with `nodes` points and its cumulative matrix.
pub(crate) fn plain_rule(nodes: usize) -> &'static GradedRule {
    static RULES: SizeTables<GradedRule> = Mutex::new(Vec::new());
    thread_local! {
        static KNOWN: KnownSizes<GradedRule> = const { RefCell::new(Vec::new()) };
    }
    built_once(&RULES, &KNOWN, nodes, GradedRule::plain)
}

/// The `nodes` Chebyshev points of a stick zone's piecewise tables and their cosine
/// transform.
pub(crate) fn chebyshev_points(nodes: usize) -> &'static ChebyshevPoints {
    static POINTS: SizeTables<ChebyshevPoints> = Mutex::new(Vec::new());
    thread_local! {
        static KNOWN: KnownSizes<ChebyshevPoints> = const { RefCell::new(Vec::new()) };
    }
    built_once(&POINTS, &KNOWN, nodes, ChebyshevPoints::new)
}

/// The table of `size` from `shared`, built by `make` on first use and kept for the process
/// (each thread's entries also in `known`, module docs).
fn built_once<T: Sync + 'static>(
    shared: &'static SizeTables<T>,
    known: &'static LocalKey<KnownSizes<T>>,
    size: usize,
    make: impl FnOnce(usize) -> T,
) -> &'static T {
    let find = |tables: &Vec<(usize, &'static T)>| {
        tables.iter().find(|(n, _)| *n == size).map(|(_, t)| *t)
    };
    if let Some(table) = known.with_borrow(find) {
        return table;
    }
    let mut tables = shared
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let table = find(&tables).unwrap_or_else(|| {
        let table: &'static T = Box::leak(Box::new(make(size)));
        tables.push((size, table));
        table
    });
    known.with_borrow_mut(|k| k.push((size, table)));
    table
}

thread_local! {
    static TRANSFORM_WORK: RefCell<Work> = RefCell::default();
    static COLUMN_SUMS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// `f` of this thread's transform buffers.
pub(crate) fn with_transform_work<R>(f: impl FnOnce(&mut Work) -> R) -> R {
    TRANSFORM_WORK.with_borrow_mut(f)
}

/// `f` of this thread's buffer of column sums.
pub(crate) fn with_column_sums<R>(f: impl FnOnce(&mut Vec<f64>) -> R) -> R {
    COLUMN_SUMS.with_borrow_mut(f)
}

thread_local! {
    /// While writing a state: the id of each shared `Arc` met, by type and address.
    pub(crate) static SERDE_WRITTEN: RefCell<Option<HashMap<(TypeId, usize), u64>>> =
        const { RefCell::new(None) };
    /// While reading a state: each shared `Arc` read, by id.
    pub(crate) static SERDE_READ: RefCell<Option<HashMap<u64, Box<dyn Any>>>> =
        const { RefCell::new(None) };
}
