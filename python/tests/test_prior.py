"""The prior language from Python: loading, compiling, errors, and derivatives."""

import warnings

import numpy as np
import pytest

import priormap


def test_library_lists_the_builtin_priors():
    names = [p["name"] for p in priormap.list_priors()]
    assert "Rectangular prior" in names and "Polygonal prior" in names


def test_compiled_gradients_match_finite_differences():
    prior = priormap.load_prior("circular")
    block = prior.blocks[0]
    rng = np.random.default_rng(3)
    k = prior.order
    x = np.concatenate([rng.uniform(1.0, 3.0, k), rng.uniform(-np.pi, np.pi, k)])
    phi = np.sort(rng.uniform(-1.0, 1.0, k))
    out = prior.evaluate(block, x, phi)
    assert out["gradients"].shape == (len(out["values"]), 2 * k)
    assert out["variables"][0] == "rho_1"
    h = 1e-6
    for v in range(2 * k):
        step = np.zeros(2 * k)
        step[v] = h
        numeric = (prior.evaluate(block, x + step, phi)["values"] -
                   prior.evaluate(block, x - step, phi)["values"]) / (2 * h)
        np.testing.assert_allclose(out["gradients"][:, v], numeric, rtol=1e-6, atol=1e-7)


def test_compile_prior_text_and_errors_with_line_and_column():
    text = ("name: Parallel walls\n"
            "specializes: Polygonal prior\n"
            "priorlet different_region:\n"
            "  alpha_2 == alpha_1 + pi\n")
    prior = priormap.compile_prior(text)
    assert prior.name == "Parallel walls"
    assert "different_region" in prior.blocks
    with pytest.raises(ValueError, match=r"<python>:4:\d+"):
        priormap.compile_prior(text.replace("alpha_1 + pi", "alpha_1 +"))
    with pytest.raises(ValueError, match="no same_region block|no different_surface block"):
        priormap.load_prior("rectangular").terms("different_surface")


def test_paths_may_be_pathlib_and_text_finds_its_parents_in_prior_path_not_the_cwd(
        tmp_path, monkeypatch):
    (tmp_path / "good.prior").write_text(
        "name: Good\nspecializes: Polygonal prior\npriorlet same_region:\n"
        "  alpha_2 == alpha_1\n")
    assert priormap.load_prior(tmp_path / "good.prior").name == "Good"
    assert "Good" in [p["name"] for p in priormap.list_priors(prior_path=[tmp_path])]
    child = "name: G2\nspecializes: Good\n"
    assert priormap.compile_prior(child, prior_path=[tmp_path]).name == "G2"
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match="unknown prior 'Good'"):
        priormap.compile_prior(child)


def test_a_prior_that_compiles_with_warnings_warns_and_keeps_them():
    text = ("name: Always\n"
            "specializes: Polygonal prior\n"
            "priorlet different_region:\n"
            "  1 <= 2\n")
    with pytest.warns(UserWarning, match=r"^<python>:4:3: this constraint uses no variable"):
        prior = priormap.compile_prior(text)
    assert len(prior.warnings) == 1 and prior.warnings[0].startswith("<python>:4:3: ")


def test_prior_warnings_reach_load_prior_and_infer_scan_and_can_be_made_errors(tmp_path):
    path = tmp_path / "always.prior"
    path.write_text("name: Always\nspecializes: Polygonal prior\n"
                    "priorlet different_region:\n  1 <= 2\n")
    with pytest.warns(UserWarning, match=r"always\.prior:4:3: "):
        priormap.load_prior(path)
    angles = np.linspace(-1.0, 1.0, 30)
    with pytest.warns(UserWarning, match=r"always\.prior:4:3: "):
        priormap.infer_scan(np.full(30, 2.0), angles, prior=path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning):
            priormap.load_prior(path)


def test_builtin_priors_compile_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for listing in priormap.list_priors():
            assert priormap.load_prior(listing["name"]).warnings == []


def test_max_curvature_is_in_inverse_metres_and_inf_without_a_bound():
    assert priormap.load_prior("polygonal").max_curvature == 0.0
    assert priormap.load_prior("circular").max_curvature == 10.0
    free = priormap.compile_prior("name: Free\norder: 2\npriorlet same_region:\n"
                                  "  alpha_2 == alpha_1\n")
    assert free.max_curvature == float("inf")


def test_docstrings_say_what_the_api_does():
    assert "<python>:line:col" in priormap.compile_prior.__doc__
    assert "inf when the prior gives none" in priormap.Prior.max_curvature.__doc__
    for name in ("cell_size", "window", "beams", "log_posterior"):
        assert name in priormap.prf_map.__doc__
