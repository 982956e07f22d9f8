"""The lab's menu (part VI.A-B), driven end to end through its streams and through a
pseudo-terminal: every case, every kind of bad answer, end of input and Ctrl-C.

In-process, the answers come from a StringIO (``interactive=False``: the menu echoes each
answer, so the output reads like the terminal session). The pseudo-terminal tests run the real
console script with a terminal on stdin, as a person would.

Every case's defaults are chosen to show a collision; the expected steps and velocities below
are worked by hand (Forward Euler moves x by v dt a step; a contact counts at distance <= 0).
"""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import pytest

from collisionlab.cli.menu import CASES
from collisionlab.scenario_file import load_scenario
from collisionlab.world import simulate
from tests.cli_helpers import SCRIPT, InterruptingStdin, files_in, finish, on_a_terminal, read_until, run_cli, typed
from tests.schema_check import check_scenario_text

#: How many questions each case asks (the lab's part VI.B, plus masses, e, dt, steps, mode).
QUESTION_COUNTS = {1: 12, 2: 12, 3: 9, 4: 10, 5: 12, 6: 12, 7: 9, 8: 9}
NO_SAVE = ("n", "n")  # "save a plot?" no; "save these answers as a scenario file?" no


def defaults(case: int, *after: str) -> str:
    """Choose ``case``, press Enter at every question, then answer ``after``."""
    return typed(str(case), *[""] * QUESTION_COUNTS[case], *after)


def prompts(out: str) -> list[str]:
    """The parameter prompts of a transcript (every line ending in ``]: answer``)."""
    return [line for line in out.splitlines() if "]: " in line or line.endswith("]:")]


# --- the case list ----------------------------------------------------------------------------
def test_the_menu_lists_the_labs_four_cases_first_numbered_as_in_the_lab() -> None:
    result = run_cli(["menu"], "")  # end of input at the first question: the list is printed
    listed = [line.split(None, 1) for line in result.lines if line.startswith("  ") and line.strip()[:1].isdigit()]
    assert listed[:4] == [
        ["1", "AABB in 3D"],
        ["2", "sphere and sphere"],
        ["3", "circle and line"],
        ["4", "sphere and plane"],
    ]
    assert len(listed) == len(CASES) > 4  # plus the others the library supports


def test_every_case_has_as_many_questions_as_the_tests_answer() -> None:
    assert {i: len(c.questions) for i, c in enumerate(CASES, start=1)} == QUESTION_COUNTS


# --- every case with its defaults: a run that shows a collision ---------------------------------
# (case, expected step, expected "velocity after" line), each worked by hand:
HAND_WORKED = {
    # 1. Boxes of edge 1 at x = 0 and 3.05, closing at 2 m/s: the gap 3.05 - 1 = 2.05 m shrinks
    #    0.02 m a step, 2.05 - 0.02 k < 0 first at k = 103. Offsets 0.2 (y) and 0.1 (z) < 1 overlap.
    #    Least penetration along x (0.01 against 0.8 and 0.9), so n = x; equal masses, e = 1:
    #    the boxes swap velocities.
    1: (103, "velocities after: box A = (-1.000, 0.000, 0.000), box B = (1.000, 0.000, 0.000) m/s"),
    # 2. Centres 3 apart in x, 0.3 in y, closing 0.02 m a step: (3 - 0.02 k)^2 + 0.09 <= 1 first at
    #    k = 103 (k >= (3 - sqrt(0.91)) / 0.02 = 102.3). Then d = (-0.94, -0.3)... from A to B
    #    n = (0.94, 0.3) / sqrt(0.9736); v_n = (vB - vA).n = -2 * 0.94 / 0.98671 = -1.90531;
    #    j = -(1 + 1) v_n / (1 + 1) = 1.90531; vA' = vA - j n = (1 - 2*0.8836/0.9736, -2*0.282/0.9736)
    #    = (-0.815, -0.579); vB' = -vA' (equal masses, zero total momentum).
    2: (103, "velocities after: sphere A = (-0.815, -0.579, 0.000), sphere B = (0.815, 0.579, 0.000) m/s"),
    # 3. y = 2.01 - 0.02 k <= r = 0.5 first at k = 76 (k >= 75.5). Lab eq. 24, n = (0, 1), e = 0.8:
    #    v' = (1, -2) - 1.8 (-2) (0, 1) = (1, 1.6).
    3: (76, "velocity after: circle = (1.000, 1.600) m/s"),
    # 4. Plane through (0,0,0), (0,0,1), (1,0,0): n = (0,0,1) x (1,0,0) = (0, 1, 0), the floor y = 0.
    #    y = 3.01 - 0.02 k <= 0.5 first at k = 126 (k >= 125.5); v' = (1, -2 + 3.6, 0.5) = (1, 1.6, 0.5).
    4: (126, "velocity after: sphere = (1.000, 1.600, 0.500) m/s"),
    # 5. Circles r = 0.5 at (0, 0) and (3, 0.4), closing 0.02 m a step: (3 - 0.02 k)^2 + 0.16 <= 1
    #    first at k = 105 (k >= (3 - sqrt(0.84)) / 0.02 = 104.2). At k = 105, d = (0.9, 0.4),
    #    |d|^2 = 0.97, n = d / |d|; j n = 2 * 0.9 (0.9, 0.4) / 0.97 = (1.670, 0.742):
    #    vA' = (1 - 1.670, -0.742) = (-0.670, -0.742), vB' = -vA'.
    5: (105, "velocities after: circle A = (-0.670, -0.742), circle B = (0.670, 0.742) m/s"),
    # 6. As case 1 in the x-y plane (offset 0.3 in y): contact at k = 103, the boxes swap velocities.
    6: (103, "velocities after: box A = (-1.000, 0.000), box B = (1.000, 0.000) m/s"),
    # 7. Sphere r = 0.5 from x = -3 at 2 m/s toward the box's face x = -1 (y = 0.5 is inside the face):
    #    touching when x + 0.5 >= -1, x = -3 + 0.02 k >= -1.5, k >= 75 exactly. In floating point
    #    seventy-five steps of 0.02 reach -1.4999999999999987 (a hair past), so contact at 75.
    #    Eq. 24 with n = (-1, 0, 0), e = 0.9: vx' = 2 - 1.9 * 2 = -1.8.
    7: (75, "velocity after: sphere = (-1.800, 0.000, 0.000) m/s"),
    # 8. Circle r = 0.5 from x = -3 at 3 m/s toward the face x = -1 (y = 0.8 inside): touching at
    #    k = 50 exactly; in floating point fifty steps of 0.03 stop at -1.500000000000006, a hair
    #    short, so the first overlap is at k = 51. vx' = 3 - 1.9 * 3 = -2.7.
    8: (51, "velocity after: circle = (-2.700, 0.000) m/s"),
}


@pytest.mark.parametrize("case", sorted(QUESTION_COUNTS))
def test_each_case_with_every_default_runs_to_the_hand_worked_collision(case: int) -> None:
    result = run_cli(["menu"], defaults(case, *NO_SAVE))
    assert result.status == 0, result.err
    assert result.err == ""
    step, velocity_line = HAND_WORKED[case]
    assert [s for s, _ in result.collisions()][:1] == [step]
    collision = result.lines.index(next(line for line in result.lines if line.startswith("collision at step")))
    assert result.lines[collision + 1].strip() == velocity_line
    assert any(line.startswith("summary: ") for line in result.lines)
    assert any("momentum" in line and "start" in line and "end" in line for line in result.lines)
    assert any("kinetic energy" in line and "start" in line and "end" in line for line in result.lines)


@pytest.mark.parametrize("case", sorted(QUESTION_COUNTS))
def test_every_prompt_shows_its_expected_form_and_a_default_in_brackets(case: int) -> None:
    result = run_cli(["menu"], defaults(case, *NO_SAVE))
    asked = prompts(result.out)
    parameter_prompts = asked[1 : 1 + QUESTION_COUNTS[case]]  # after "case (1-8) [4]:"
    assert len(parameter_prompts) == QUESTION_COUNTS[case]
    for prompt, question in zip(parameter_prompts, CASES[case - 1].questions, strict=True):
        assert prompt.startswith(f"{question.text} ({question.form}) [{question.default}]:"), prompt
        assert question.form and question.default


def test_the_lab_cases_ask_what_part_vi_b_lists() -> None:
    keys = {i: [q.key for q in CASES[i - 1].questions] for i in (1, 2, 3, 4)}
    for case in (1, 2):  # both bodies: position, extent, velocity; and masses
        for body in ("a", "b"):
            assert [k for k in keys[case] if k.startswith(body + ".")] == [
                f"{body}.position",
                f"{body}.{'size' if case == 1 else 'radius'}",
                f"{body}.velocity",
                f"{body}.mass",
            ]
    assert {"a.position", "a.radius", "a.velocity", "line.direction", "line.point", "restitution"} <= set(keys[3])
    assert {"a.position", "a.radius", "a.velocity", "p1", "p2", "p3", "restitution"} <= set(keys[4])
    for asked in keys.values():
        assert {"dt", "steps"} <= set(asked)


def test_the_forms_say_how_many_numbers() -> None:
    result = run_cli(["menu"], defaults(4, *NO_SAVE))
    assert "initial position of the sphere (x y z, three numbers) [0 3.01 0]: " in result.out
    result = run_cli(["menu"], defaults(3, *NO_SAVE))
    assert "initial position of the circle (x y, two numbers) [0 2.01]: " in result.out


def test_enter_at_the_case_question_takes_its_default() -> None:
    result = run_cli(["menu"], typed("", *[""] * QUESTION_COUNTS[4], *NO_SAVE))
    assert result.status == 0
    assert "Menu: sphere and plane" in result.out


def test_answers_typed_in_replace_the_defaults() -> None:
    # Circle r = 0.5 at (0, 1) falling at 1 m/s onto the x axis, dt = 0.1: y = 1 - 0.1 k <= 0.5 at
    # k = 5 exactly; in floating point five steps of -0.1 stop at 0.5000000000000001, a hair above,
    # so the contact comes one step later, at k = 6. e = 0.5: v' = (0, -1) - 1.5 (-1) (0, 1) = (0, 0.5).
    text = typed("3", "0 1", "0.5", "0, -1", "1 0", "0 0", "0.5", "0.1", "10", "euler", *NO_SAVE)
    result = run_cli(["menu"], text)
    assert result.status == 0, result.err
    assert result.collisions()[0][0] == 6
    assert "velocity after: circle = (0.000, 0.500) m/s" in result.out


def test_exact_mode_can_be_chosen() -> None:
    text = typed("4", *[""] * (QUESTION_COUNTS[4] - 1), "exact", *NO_SAVE)
    result = run_cli(["menu"], text)
    assert result.status == 0
    assert "mode exact" in result.out
    # exact time of impact: y = 3.01 - 2 t = 0.5 at t = 1.255 s, inside step 126
    assert "collision at step 126 (t = 1.255 s): sphere hits plane" in result.out


# --- bad answers: a one-line reason, then the same question again -------------------------------
# (case, index of the question answered badly, bad answer, words of the reason)
BAD_ANSWERS = [
    (4, 0, "abc", "'abc' is not a number"),
    (4, 0, "one two three", "'one' is not a number"),
    (4, 0, "1 2", "expected 3 numbers"),
    (4, 0, "1 2 3 4", "expected 3 numbers"),
    (3, 0, "1 2 3", "expected 2 numbers"),
    (4, 0, "nan 0 0", "finite"),
    (4, 0, "0 inf 0", "finite"),
    (4, 0, "0 0 -inf", "finite"),
    (4, 1, "0", "must be > 0"),
    (4, 1, "-0.5", "must be > 0"),
    (4, 1, "nan", "finite"),
    (4, 1, "big", "'big' is not a number"),
    (4, 1, "1 2", "expected one number"),
    (3, 3, "0 0", "zero vector"),
    (4, 5, "0 0 0", "collinear or coincident"),  # p3 equal to p1
    (4, 5, "0 0 7", "collinear or coincident"),  # p3 on the line through p1 = 0 0 0 and p2 = 0 0 1
    (4, 5, "0 0 -1e-30", "collinear or coincident"),
    (4, 6, "-0.1", "must be >= 0"),
    (3, 5, "-1", "must be >= 0"),
    (3, 5, "e", "'e' is not a number"),
    (3, 6, "0", "must be > 0"),  # dt
    (3, 6, "-0.01", "must be > 0"),
    (3, 7, "1.5", "whole number"),  # steps
    (3, 7, "0", "whole number"),
    (3, 8, "fast", "euler"),  # mode
    (1, 1, "1 0 1", "must be > 0"),  # a box's extent
    (1, 3, "0", "must be > 0"),  # mass
    (2, 3, "-2", "must be > 0"),
]


@pytest.mark.parametrize(("case", "index", "bad", "reason"), BAD_ANSWERS)
def test_a_bad_answer_gives_a_one_line_reason_and_the_question_again(
    case: int, index: int, bad: str, reason: str
) -> None:
    answers = [str(case), *[""] * index, bad, *[""] * (QUESTION_COUNTS[case] - index), *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0, result.err
    assert "Traceback" not in result.out + result.err
    question = CASES[case - 1].questions[index]
    prompt = f"{question.text} ({question.form}) [{question.default}]: "
    lines = result.lines
    where = lines.index(prompt + bad)
    assert lines[where + 1].startswith("  ! ") and reason in lines[where + 1], lines[where + 1]
    assert lines[where + 1].endswith("try again")
    assert lines[where + 2] == prompt  # asked again; Enter then takes the default
    # ... and the run goes on with the default, as if the bad answer had never been typed
    assert result.collisions()[0][0] == HAND_WORKED[case][0]


@pytest.mark.parametrize("bad", ["0", "9", "x", "-1", "1.5", "four"])
def test_a_bad_case_number_is_asked_again(bad: str) -> None:
    result = run_cli(["menu"], typed(bad, *defaults(4, *NO_SAVE).splitlines()))
    assert result.status == 0
    lines = result.lines
    where = lines.index(f"case (1-{len(CASES)}) [4]: {bad}")
    assert lines[where + 1] == f"  ! case: expected a number from 1 to {len(CASES)}; try again"
    assert lines[where + 2].startswith("case (1-")


def test_several_bad_answers_in_a_row_are_each_refused() -> None:
    answers = ["4", "x", "1", "nan nan nan", "", "0", "-3", "", *[""] * (QUESTION_COUNTS[4] - 2), *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0
    assert sum(line.startswith("  ! ") for line in result.lines) == 5


def test_restitution_above_one_is_accepted_with_a_warning_that_energy_grows() -> None:
    # Case 3 with e = 2: v' = (1, -2) - (1 + 2)(-2)(0, 1) = (1, 4); KE 2.5 J -> 8.5 J.
    answers = ["3", *[""] * 5, "2", *[""] * 3, *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0
    lines = result.lines
    where = lines.index("coefficient of restitution e (a number >= 0; 1 elastic, 0 sticks) [0.8]: 2")
    assert "warning" in lines[where + 1] and "kinetic energy will grow" in lines[where + 1]
    assert lines[where + 2].startswith("time step dt")  # accepted: the next question
    assert "velocity after: circle = (1.000, 4.000) m/s" in result.out
    assert "kinetic energy  start 2.5 J   end 8.5 J" in result.out


def test_restitution_of_exactly_one_and_zero_give_no_warning() -> None:
    for e in ("1", "0"):
        result = run_cli(["menu"], typed("3", *[""] * 5, e, *[""] * 3, *NO_SAVE))
        assert result.status == 0
        assert "warning" not in result.out


# --- end of input and Ctrl-C ----------------------------------------------------------------------
@pytest.mark.parametrize("answered", [0, 1, 4, 10, 11, 12])
def test_end_of_input_anywhere_exits_1_with_a_message_and_no_traceback(answered: int) -> None:
    # 0: at the case question; 1..10: within the parameters of case 4; 11, 12: at the save questions
    answers = defaults(4, *NO_SAVE).splitlines()[:answered]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 1
    assert "end of input" in result.err
    assert "Traceback" not in result.out + result.err


def test_end_of_input_in_the_middle_of_a_line_is_still_an_answer() -> None:
    # The last answer without its newline is used, then the next question meets the end.
    result = run_cli(["menu"], "4\n0 3.01 0")
    assert result.status == 1
    assert "radius of the sphere" in result.out


@pytest.mark.parametrize("answered", [0, 3, 10, 11])
def test_ctrl_c_at_a_prompt_exits_130_without_a_traceback(answered: int) -> None:
    stdin = InterruptingStdin(typed(*defaults(4, *NO_SAVE).splitlines()[:answered]))
    result = run_cli(["menu"], stdin)
    assert result.status == 130
    assert "interrupted" in result.err
    assert "Traceback" not in result.out + result.err


def test_ctrl_c_while_the_answers_are_checked_exits_130(monkeypatch: pytest.MonkeyPatch) -> None:
    """Ctrl-C can land anywhere, not only inside readline: here in the run itself."""
    import collisionlab.cli.menu as menu

    class Interrupted:
        compiled = False

        def __init__(self, scenario: object) -> None:
            pass

        def load_kernels(self) -> float:
            return 0.0

        def run(self, **_: object) -> None:
            raise KeyboardInterrupt

    monkeypatch.setattr(menu, "World", Interrupted)
    result = run_cli(["menu"], defaults(4, *NO_SAVE))
    assert result.status == 130
    assert "Traceback" not in result.err


# --- saving the answers as a scenario file ----------------------------------------------------------
@pytest.mark.parametrize("case", sorted(QUESTION_COUNTS))
def test_the_saved_scenario_file_loads_and_runs_to_the_same_events(case: int, tmp_path: Path) -> None:
    path = tmp_path / "answers.toml"
    result = run_cli(["menu"], defaults(case, "n", "y", str(path)))
    assert result.status == 0, result.err
    assert f"wrote {path}\nrun it again with: collisionlab run {path}" in result.out
    assert files_in(tmp_path) == ["answers.toml"]  # no temporary file left beside it
    check_scenario_text(path.read_text(encoding="utf-8"))
    rerun = run_cli(["run", str(path)])
    assert rerun.status == 0, rerun.err
    menu_run = result.out[result.out.index("Menu: ") : result.out.index("save a plot?")]
    assert rerun.out == menu_run  # the same table, collisions, velocities and summary
    record = simulate(load_scenario(path))
    assert [e.step for e in record.events] == [s for s, _ in result.collisions()]


def test_the_saved_file_keeps_typed_answers(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    text = typed("3", "0 1", "0.25", "0.5 -1", "1 1", "0 -0.5", "0.3", "0.02", "40", "exact", "n", "y", str(path))
    assert run_cli(["menu"], text).status == 0
    scenario = load_scenario(path)
    (body,) = scenario.bodies
    (line,) = scenario.obstacles
    assert body.position.as_tuple() == (0.0, 1.0, 0.0) and body.shape.radius == 0.25
    assert body.velocity.as_tuple() == (0.5, -1.0, 0.0)
    assert line.shape.point.as_tuple() == (0.0, -0.5, 0.0)
    settings = scenario.settings
    assert (settings.restitution, settings.dt, settings.steps, settings.mode) == (0.3, 0.02, 40, "exact")


def test_a_scenario_file_that_cannot_be_written_is_asked_for_again(tmp_path: Path) -> None:
    bad = tmp_path / "no such folder" / "x.toml"
    good = tmp_path / "ok.toml"
    result = run_cli(["menu"], defaults(4, "n", "y", str(bad), str(good)))
    assert result.status == 0, result.err
    assert f"  ! cannot write {bad}" in result.out
    assert good.exists() and not bad.parent.exists()


def test_the_default_scenario_file_name_is_used_on_enter(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = run_cli(["menu"], defaults(4, "", "yes", ""))
    assert result.status == 0
    assert files_in(tmp_path) == ["scenario.toml"]


def test_a_bad_yes_no_answer_is_asked_again() -> None:
    result = run_cli(["menu"], defaults(4, "maybe", "n", "n"))
    assert result.status == 0
    assert "  ! answer y or n" in result.lines


# --- how the menu is reached -----------------------------------------------------------------------
def test_no_arguments_on_a_terminal_opens_the_menu() -> None:
    result = run_cli([], defaults(4, *NO_SAVE), interactive=True)
    assert result.status == 0
    assert result.out.startswith("collisionlab: collision detection and resolution")
    assert "collision at step 126" in result.out


def test_no_arguments_from_a_pipe_is_a_usage_error_that_points_at_the_menu() -> None:
    result = run_cli([], defaults(4, *NO_SAVE), interactive=False)
    assert result.status == 2
    assert "collisionlab menu" in result.err
    assert result.out == ""


# --- the real console script on a pseudo-terminal ---------------------------------------------------
def test_the_bare_console_script_on_a_terminal_runs_the_menu(tmp_path: Path) -> None:
    with on_a_terminal([], tmp_path) as (process, master):
        read_until(master, b"case (1-8) [4]: ")
        os.write(master, b"3\n")
        for _ in range(QUESTION_COUNTS[3]):
            read_until(master, b"]: ")
            os.write(master, b"\n")
        output = read_until(master, b"save a plot? [y/N]: ")
        os.write(master, b"n\n")
        read_until(master, b"scenario file? [y/N]: ")
        os.write(master, b"n\n")
        status, err = finish(process)
    assert status == 0, err
    assert b"collision at step 76 (t = 0.760 s): circle hits line" in output
    assert b"velocity after: circle = (1.000, 1.600) m/s" in output
    assert b"Traceback" not in err


def test_ctrl_c_at_a_prompt_on_a_terminal_exits_130(tmp_path: Path) -> None:
    with on_a_terminal([], tmp_path) as (process, master):
        read_until(master, b"case (1-8) [4]: ")
        os.write(master, b"4\n")
        read_until(master, b"initial position of the sphere")
        process.send_signal(signal.SIGINT)
        status, err = finish(process)
    assert status == 130
    assert b"interrupted" in err
    assert b"Traceback" not in err


def test_end_of_input_on_a_terminal_exits_1(tmp_path: Path) -> None:
    with on_a_terminal([], tmp_path) as (process, master):
        read_until(master, b"case (1-8) [4]: ")
        os.write(master, b"\x04")  # Ctrl-D at the start of a line: end of input
        status, err = finish(process)
    assert status == 1
    assert b"end of input" in err
    assert b"Traceback" not in err


def test_the_menu_subcommand_reads_answers_from_a_pipe() -> None:
    process = subprocess.run(
        [str(SCRIPT), "menu"], input=defaults(1, *NO_SAVE), capture_output=True, text=True, timeout=30, check=False
    )
    assert process.returncode == 0, process.stderr
    assert "collision at step 103 (t = 1.030 s): box A and box B collide" in process.stdout


def test_a_plot_file_that_cannot_be_written_is_asked_again(tmp_path: Path) -> None:
    # Case 3 on defaults, then "save a plot? y": a missing folder and a wrong extension are
    # refused with a reason and asked again; the third name is written.
    good = tmp_path / "plot.png"
    answers = ["3", *[""] * 9, "y", str(tmp_path / "missing" / "p.png"), str(tmp_path / "p.txt"), str(good), "n"]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0, result.err
    assert result.out.count("try again") >= 2
    assert good.exists() and good.stat().st_size > 0
    assert not (tmp_path / "p.txt").exists()


# --- issue 11 ------------------------------------------------------------------------------------
LARGEST, SMALLEST = "the largest collisionlab simulates", "the smallest collisionlab simulates"


@pytest.mark.parametrize(
    ("case", "index", "bad", "line"),
    [
        (4, 0, "a 0 0", "  ! position: 'a' is not a number; try again"),
        (4, 2, "1 x 0", "  ! velocity: 'x' is not a number; try again"),
        (4, 3, "0 0", "  ! point 1: expected 3 numbers like 'x y z', got 2; try again"),
        (3, 4, "0 zero", "  ! point: 'zero' is not a number; try again"),
        (1, 0, "1 1 nan", "  ! position: must be a finite number (got nan); try again"),
        (2, 2, "1e200 0 0", f"  ! velocity: must be at most 1e+09 m/s, {LARGEST} (got 1e+200); try again"),
        (2, 1, "1e-300", f"  ! radius: must be at least 1e-06 m, {SMALLEST} (got 1e-300); try again"),
    ],
)  # fmt: skip
def test_a_bad_vector_answer_names_its_field(case: int, index: int, bad: str, line: str) -> None:
    # Vector errors used to name nothing: "! 'a' is not a number".
    answers = [str(case), *[""] * index, bad, *[""] * (QUESTION_COUNTS[case] - index), *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0, result.err
    where = next(i for i, text in enumerate(result.lines) if text.endswith(f"]: {bad}"))
    assert result.lines[where + 1] == line


def test_the_default_third_point_is_never_collinear_with_the_first_two() -> None:
    # Points (1, 0, 0) and (2, 0, 0): the fixed default (1, 0, 0) for the third point was the
    # first point again, so Enter gave "collinear" forever. The default offered now spans a plane.
    answers = ["4", "", "", "", "1 0 0", "2 0 0", "", *[""] * 4, *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0, result.err
    third = next(text for text in result.lines if text.startswith("third point on the plane"))
    offered = third.split("[", 1)[1].split("]", 1)[0]
    assert offered != "1 0 0"
    assert not any(text.startswith("  ! ") for text in result.lines)
    assert any(text.startswith("summary: ") for text in result.lines)


def test_a_box_position_is_said_to_be_its_centre() -> None:
    for case in (1, 6):
        texts = [q.text for q in CASES[case - 1].questions if q.key.endswith(".position")]
        assert texts and all("centre" in text for text in texts)


def test_steps_beyond_what_fits_are_asked_again() -> None:
    # Two bodies: at most 1,000,000 steps (2,000,000 body-steps of frames kept in memory).
    answers = ["2", *[""] * 10, "1500000", "", "", *NO_SAVE]
    result = run_cli(["menu"], typed(*answers))
    assert result.status == 0, result.err
    assert "  ! steps: must be at most 1e+06" in result.out
