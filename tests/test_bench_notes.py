"""The translate bench says why a peer's iterations exceed 1.5 × exact IPOPT's, and names
the machine it ran on."""

from pathlib import Path

from flipkit.experiments.speed import TRANSLATE_SOLVERS
from bench.iteration_notes import ITERATION_RATIO, iteration_notes


def _row(iterations, profile):
    return {"iterations": iterations, "profile": profile}


def test_a_peer_over_the_ratio_gets_its_profile_beside_ipopts():
    names = ("sqp", "fatrop", "ipopt_exact", "ipopt")
    prof = lambda it, reg, short: {"iterations": it, "regularised": reg,  # noqa: E731
                                   "short_steps": short}
    rows = [{"sqp": _row(9, None), "fatrop": _row(80, prof(80, 50, 20)),
             "ipopt_exact": _row(25, prof(25, 1, 5)), "ipopt": _row(30, None)},
            {"sqp": _row(8, None), "fatrop": _row(90, prof(90, 60, 30)),
             "ipopt_exact": _row(27, prof(27, 0, 6)), "ipopt": _row(36, None)}]
    med = {"sqp": {"iterations": 8.5}, "fatrop": {"iterations": 85.0},
           "ipopt_exact": {"iterations": 26.0}, "ipopt": {"iterations": 33.0}}
    lines = iteration_notes(rows, names, med, TRANSLATE_SOLVERS)
    assert len(lines) == 1 and lines[0].startswith("FATROP: median 85 iterations, 3.3 ×")
    assert "110 of its 170" in lines[0] and "exact IPOPT: 1 of 52" in lines[0]
    assert "below half on 50 (11)" in lines[0]
    med["fatrop"]["iterations"] = ITERATION_RATIO * 26.0  # at the ratio: no note
    assert iteration_notes(rows, names, med, TRANSLATE_SOLVERS) == []


def test_a_peer_without_a_profile_is_said_to_be_so():
    names = ("ipopt_exact", "ipopt")
    rows = [{"ipopt_exact": _row(20, None), "ipopt": _row(50, None)}]
    med = {"ipopt_exact": {"iterations": 20.0}, "ipopt": {"iterations": 50.0}}
    assert iteration_notes(rows, names, med, TRANSLATE_SOLVERS)[0].endswith("not profiled")


def test_the_machine_line_names_the_cpu_and_its_simd_kernels():
    """The bench's machine line names the CPU model (from /proc/cpuinfo) and whether numpy's
    loops use AVX-512, on which the last bits of a plan depend."""
    from numpy._core._multiarray_umath import __cpu_features__

    from bench import bench

    line = bench.machine()
    assert line.startswith("machine: ") and "Python " in line
    simd = ", AVX-512" if __cpu_features__.get("AVX512_SKX") else ", no AVX-512"
    assert bench.cpu_model().endswith(simd)
    model = Path("/proc/cpuinfo")
    if model.is_file():
        names = [ln.split(":", 1)[1].strip() for ln in model.read_text().splitlines()
                 if ln.startswith("model name")]
        if names:
            assert bench.cpu_model() == names[0] + simd
