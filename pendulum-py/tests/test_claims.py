"""``pendulum.check_claims``: claims files against the built-in sympy reference."""

from pathlib import Path

import pytest

import pendulum

CLAIMS = Path(__file__).resolve().parents[2] / "reference" / "claims"


def test_the_textbook_slip_is_found_and_corrected():
    report = pendulum.check_claims(CLAIMS / "double-pendulum.claims")
    (claim,) = report.claims
    assert (claim.title, claim.verdict, claim.cases) == ("Double pendulum, as in my textbook", "disagrees", ["planar_n2"])
    assert claim.worst == pytest.approx(1.0, abs=0.01)  # −x against x: relative error ≈ 1
    assert claim.diagnosis == "the overall sign: the reference is −1 × the claim"
    assert claim.fixes == [(7, claim.diagnosis, "c[2] = -m[2] l[1] l[2] θ̇[1]^2 sin(θ[1] - θ[2])")]
    assert "| Double pendulum, as in my textbook | planar n = 2 (1 case) | disagrees |" in report.table


def test_a_corrected_claim_agrees_and_errors_name_their_place():
    text = (CLAIMS / "double-pendulum.claims").read_text().replace(
        "c[2] = m[2] l[1] l[2] θ̇[1]^2", "c[2] = -m[2] l[1] l[2] θ̇[1]^2")
    (claim,) = pendulum.check_claims(text=text, states=20).claims
    assert claim.verdict == "agrees" and claim.worst < 1e-12 and claim.diagnosis == "–"
    with pytest.raises(ValueError, match=r"1 error in <text>:\n<text>:3:"):
        pendulum.check_claims(text='claim "x"\n  chain planar, n = 2\n  M[1,1] = (m[1] +\n')
    with pytest.raises(ValueError, match="give a claims file's path or its text"):
        pendulum.check_claims()
    with pytest.raises(ValueError, match="cannot read"):
        pendulum.check_claims(CLAIMS / "missing.claims")


def test_the_documents_claims_have_the_verdicts_of_the_errata():
    report = pendulum.check_claims(CLAIMS / "seed.claims", states=20)
    verdicts = [c.verdict for c in report.claims]
    # 33 claims on the document's equations; the 10 that disagree are reference/ERRATA.md's.
    assert len(verdicts) == 33 and set(verdicts) <= {"agrees", "disagrees"}
    assert verdicts.count("disagrees") == 10
    assert all(c.diagnosis != "–" for c in report.claims if c.verdict == "disagrees")
