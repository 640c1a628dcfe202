"""The command-line contract of `roastlab simulate` and `roastlab plant`."""

import json
import subprocess
import sys

import numpy as np
import pytest

HEADER = "time_s,Gg_kg_s,Tgi_C,Ta_C\n"


def write_inputs(path, rows):
    path.write_text(HEADER + "".join(",".join(str(v) for v in r) + "\n" for r in rows))
    return path


@pytest.fixture
def check_inputs(tmp_path):
    return write_inputs(tmp_path / "in.csv", [(t, 0.4, 450, 30) for t in range(0, 901, 30)])


def test_simulate_reproduces_check_value(cli, tmp_path, check_inputs):
    out = tmp_path / "out.csv"
    code, stdout, stderr = cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", out)
    assert code == 0, stderr
    lines = out.read_text().splitlines()
    assert lines[0] == "time_s,Tb_C,Tm_C,X_kg_kg,He_kJ_kg,Ta_C,Tgo_C"
    assert len(lines) == 1 + 31
    last = [float(v) for v in lines[-1].split(",")]
    assert abs(last[1] - 218.31) < 0.01 and abs(last[5] - 210.72) < 0.01
    assert "218.31" in stdout


def test_theta_json_and_overrides(cli, tmp_path, check_inputs):
    theta = tmp_path / "theta.json"
    theta.write_text(json.dumps({"hgm": 0.1, "hbm": 0.1, "Pbm": 0.6, "SSR": 1.0}))
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", a, "--theta", theta)[0] == 0
    assert (
        cli(
            "simulate",
            "--plant",
            "120kg",
            "--inputs",
            check_inputs,
            "--out",
            b,
            "--hgm",
            "0.1",
            "--hbm",
            "0.1",
            "--pbm",
            "0.6",
        )[0]
        == 0
    )
    assert a.read_text() == b.read_text()
    c = tmp_path / "c.csv"
    assert cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", c)[0] == 0
    assert c.read_text() != a.read_text()


def test_options_change_results(cli, tmp_path, check_inputs):
    base = tmp_path / "base.csv"
    cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", base)
    for opt in (["--tb0", "25"], ["--tm0", "100"], ["--x0", "0.12"], ["--moisture", "printed"], ["--plant", "360kg"]):
        out = tmp_path / "o.csv"
        args = ["simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", out] + opt
        code, _, err = cli(*args)
        assert code == 0, err
        assert out.read_text() != base.read_text(), opt


def test_plant_toml_and_json_output(cli, tmp_path, check_inputs):
    plant = tmp_path / "p.toml"
    plant.write_text(
        'name = "mine"\nMb_kg = 120\nDch_m = 1.24\nLch_m = 1.335\nHflap_m = 0.3\nSflap_m = 0.1\nMm_kg = 2000\n'
    )
    a, b = tmp_path / "a.csv", tmp_path / "b.json"
    assert cli("simulate", "--plant", plant, "--inputs", check_inputs, "--out", a)[0] == 0
    assert cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", b, "--heat-flows")[0] == 0
    payload = json.loads(b.read_text())
    assert "Qgb_kW" in payload["columns"]
    assert abs(payload["columns"]["Tb_C"][-1] - float(a.read_text().splitlines()[-1].split(",")[1])) < 1e-5


def test_plant_command_prints_derived(cli):
    code, out, _ = cli("plant", "120kg")
    assert code == 0
    assert "Agm" in out and "23.22" in out and "Mbd" in out


@pytest.mark.parametrize(
    "content, needle",
    [
        ("", "empty file"),
        (HEADER, "header only"),
        ("time_s,Gg_kg_s\n0,0.4\n", "missing column(s) Tgi_C"),
        (HEADER + "0,0.4,450,30\n30,abc,450,30\n", "line 3, column Gg_kg_s: not a number"),
        (HEADER + "0,0.4,450,30\n30,nan,450,30\n", "NaN"),
        (HEADER + "0,0.4,450,30\n0,0.4,450,30\n", "time not strictly increasing"),
        (HEADER + "0,0.4,450,30\n30,0,450,30\n", "Gg_kg_s (inlet gas mass flow) = 0 kg/s outside"),
        (HEADER + "0,0.4,450,30\n30,0.4\n", "truncated"),
    ],
)
def test_bad_inputs_one_line_exit_2(cli, tmp_path, content, needle):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    out = tmp_path / "out.csv"
    code, _, err = cli("simulate", "--plant", "120kg", "--inputs", bad, "--out", out)
    assert code == 2
    assert err.count("\n") == 1 and "bad.csv" in err and needle in err, err
    assert not out.exists()


@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--plant", "999kg"], "unknown plant preset"),
        (["--pbm", "1.5"], "Pbm must be in (0, 1)"),
        (["--theta", "missing.json"], "missing.json: file not found"),
    ],
)
def test_bad_options(cli, tmp_path, check_inputs, extra, needle):
    args = ["simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", tmp_path / "o.csv"] + extra
    code, _, err = cli(*args)
    assert code == 2 and needle in err and err.count("\n") == 1, err


def test_negative_geometry(cli, tmp_path, check_inputs):
    plant = tmp_path / "neg.toml"
    plant.write_text("Mb_kg = 120\nDch_m = -1.24\nLch_m = 1.335\nHflap_m = 0.3\nSflap_m = 0.1\nMm_kg = 2000\n")
    code, _, err = cli("simulate", "--plant", plant, "--inputs", check_inputs, "--out", tmp_path / "o.csv")
    assert code == 2 and "neg.toml: Dch_m" in err and "outside the plausible range 0.02..10 m" in err


def test_second_cli_process_uses_disk_cache(tmp_path, check_inputs):
    """The compiled kernel is loaded from numba's on-disk cache in a fresh process."""
    code = (
        "import sys; from roastlab.cli import main; main(sys.argv[1:]);"
        "from roastlab.sim.kernels import simulate_population_kernel as f; print('HITS', sum(f.stats.cache_hits.values()), 'MISSES', sum(f.stats.cache_misses.values()))"
    )
    args = [
        sys.executable,
        "-c",
        code,
        "simulate",
        "--plant",
        "120kg",
        "--inputs",
        str(check_inputs),
        "--out",
        str(tmp_path / "o.csv"),
    ]
    subprocess.run(args, check=True, capture_output=True)
    second = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    assert "HITS 1 MISSES 0" in second, second


def test_simulation_result_frame_and_plot(tmp_path):
    from roastlab import simulate

    t = np.arange(0, 601, 30.0)
    r = simulate("120kg", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    frame = r.to_frame(heat_flows=True)
    assert list(frame.columns)[:7] == ["time_s", "Tb_C", "Tm_C", "X_kg_kg", "He_kJ_kg", "Ta_C", "Tgo_C"]
    assert {"Qgb_kW", "Qgm_kW", "Qbm_kW", "Qr_kW"} <= set(frame.columns)
    r.plot(tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"


def test_the_csv_and_json_of_a_trace_are_what_pandas_writes_of_its_frame():
    """to_csv_text writes the trace without importing pandas (half a second of every command's start);
    byte for byte what pandas' to_csv(float_format="%.6f") of the same frame writes, and to_json_dict
    its rounded columns, for the paper's run with heat flows and for a heater and fan (integer
    settings among them) with a band holding missing values."""
    from types import SimpleNamespace

    import pandas as pd

    from roastlab import simulate

    t = np.arange(0, 601, 30.0)
    paper = simulate("120kg", t, np.full_like(t, 0.4), np.full_like(t, 450.0))
    heater = np.where(t < 300, 7, 5)  # whole settings: an integer column
    driven = simulate(
        "120kg", t, np.full_like(t, 0.4), np.full_like(t, 25.0), heater=heater, fan=np.full_like(t, 40.5),
        values={"Qe_gain_kW": 30.0},
    )  # fmt: skip
    lower = driven.Ta_C - 5.0
    lower[3] = np.nan
    driven.band = SimpleNamespace(lower_C=lower, upper_C=driven.Ta_C + 5.0)
    driven.heater = heater  # simulate keeps settings as floats; a caller's result may hold whole ones
    for r, flows in ((paper, True), (driven, False)):
        frame = r.to_frame(heat_flows=flows)
        assert r.to_csv_text(heat_flows=flows) == frame.to_csv(index=False, float_format="%.6f", lineterminator="\n")
        doc = r.to_json_dict(heat_flows=flows)["columns"]
        assert list(doc) == list(frame.columns)
        for c in frame.columns:
            assert doc[c] == frame[c].round(6).tolist() or np.allclose(doc[c], frame[c].round(6), equal_nan=True), c
    assert pd.api.types.is_integer_dtype(driven.to_frame()["heater"]) and "\n0.000000,30.000000," in paper.to_csv_text()


def test_batch_green_weight_overrides_plant(cli, tmp_path, check_inputs):
    """A '# Mb_kg' line (written by roastlab import) sets the batch mass for that batch."""
    plain, heavy, explicit = tmp_path / "a.csv", tmp_path / "b.csv", tmp_path / "c.csv"
    cli("simulate", "--plant", "120kg", "--inputs", check_inputs, "--out", plain)
    half = tmp_path / "half.csv"
    half.write_text("# Mb_kg = 60\n" + check_inputs.read_text())
    cli("simulate", "--plant", "120kg", "--inputs", half, "--out", heavy)
    plant = tmp_path / "p.toml"
    plant.write_text("Mb_kg = 60\nDch_m = 1.24\nLch_m = 1.335\nHflap_m = 0.3\nSflap_m = 0.1\nMm_kg = 2000\n")
    cli("simulate", "--plant", plant, "--inputs", check_inputs, "--out", explicit)
    assert heavy.read_text() != plain.read_text()
    assert heavy.read_text() == explicit.read_text()


def test_every_subcommand_help_names_the_model_file():
    from roastlab.cli import build_parser

    parser = build_parser()
    assert "MODEL.json" in parser.format_help()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name, p in sub.choices.items():
        text = p.format_help()
        for inner in (a for a in p._actions if a.dest == "what"):
            text += "".join(q.format_help() for q in inner.choices.values())
        assert "MODEL.json" in text, name


def test_a_signed_change_is_read_as_the_value_of_its_option():
    # "--heater -1@5:00", as the whatif help writes it, failed with "expected one argument"
    from roastlab.cli import build_parser

    parser = build_parser()
    args = parser.parse_args(
        ["whatif", "roast.json", "--model", "m.json", "--heater", "-1@5:00", "--fan", "-2", "--tgi", "-3.5"]
    )
    assert (args.heater, args.fan, args.tgi) == ("-1@5:00", "-2", -3.5)
    args = parser.parse_args(
        ["whatif", "roast.json", "--model", "m.json", "--set", "heater=-1@2:00", "--set", "-1@3:00"]
    )
    assert args.set == ["heater=-1@2:00", "-1@3:00"]
    # a dash-led word that is not a signed number is still an option: a missing value says so
    with pytest.raises(SystemExit) as e:
        parser.parse_args(["whatif", "roast.json", "--model", "m.json", "--heater", "--band"])
    assert e.value.code == 2
