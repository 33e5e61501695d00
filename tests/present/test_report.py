"""The text report of `pdw walk` (pdw.present.report): next to the paper's numbers it says why
they differ (issue 26 item 15; docs/reproduction.md section 4)."""
import pdw
from pdw.present.report import walk_report


def test_the_paper_comparison_says_why_the_numbers_differ():
    text = walk_report(pdw.simulate(t_end=1.5))                 # the paper's walker, d_hip = 0.018
    table = text.split("vs the paper:")[1]
    why = table.split("\n\n")[0]
    assert "at the paper's d_hip = 0.018 there is no periodic gait" in why
    assert "decaying transient" in why and "docs/reproduction.md" in why
    assert "--preset paper_steady" in why


def test_the_steady_preset_names_its_own_difference():
    r = pdw.simulate(t_end=3.0, params=pdw.Params.paper_steady())
    why = walk_report(r).split("vs the paper:")[1].split("\n\n")[0]
    assert "7-9 % shorter and quicker" in why and "no periodic gait" in why
    other = walk_report(pdw.simulate(t_end=1.5, params=pdw.Params.paper().replace(k_hip=0.9)))
    assert "these parameters differ from it" in other
    assert "decaying transient" not in other
