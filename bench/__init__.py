"""The benchmarks and profilers: scripts that measure flipkit (solve times, iterations, where
an iteration's time goes, the command streams of many plans), kept out of the installed
package. Run from the repository root, e.g. ``python -m bench.bench translate`` (see
``bench/README.md``)."""
