//! `rt-e2e` (`publish = false`): the cross-crate end-to-end tests in `tests/tests/`, which need
//! the whole pipeline (scene loading, the default acceleration structure, integrators, film):
//! white furnaces, agreement of estimators, convergence rate, determinism, progressive passes,
//! skipped work, and the short run of the numerical stress suite. Their helpers are in
//! `rt-testkit`; the stress suite and self-hit counters are in `rt-validate`. This library is
//! empty.

#![forbid(unsafe_code)]
