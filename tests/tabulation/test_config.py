"""Build configuration: presets, TOML parsing, errors naming the key."""

import pytest

from tests.helpers.cli import user_error

from tablegen.cli import main as tablegen_main
from tablegen.tabulation.config import PRESETS, ConfigError, load_config, parse_config, wall_preset_text, wall_presets
from direct_model.wall import CORUNDUM_ON_STEEL, WallMaterial


@pytest.mark.parametrize("preset", PRESETS)
def test_presets_parse_and_round_trip(preset):
    config = load_config(preset=preset)
    assert parse_config(config.to_toml()) == config
    assert config.alpha1_deg[-1] == 90.0
    assert max(b - a for a, b in zip(config.alpha1_deg, config.alpha1_deg[1:])) <= 5.0


def test_production_and_paper_presets_meet_their_definitions():
    prod = load_config(preset="production")
    assert max(b - a for a, b in zip(prod.alpha1_deg, prod.alpha1_deg[1:])) <= 2.5
    assert max(b - a for a, b in zip(prod.speed_m_s, prod.speed_m_s[1:])) <= 25.0
    assert prod.particles_per_cell >= 200_000
    paper = load_config(preset="paper")
    assert paper.speed_m_s == (200.0,) and paper.particles_per_cell == 10 ** 8 and len(paper.shapes) == 4


def test_wall_law_defaults_to_corundum_on_steel_and_round_trips():
    assert load_config().wall == CORUNDUM_ON_STEEL
    config = parse_config('[wall]\nk = 0.2\np = 0.5\nq = -0.5\nname = "glass \\"A\\" on steel"\n')
    assert config.wall == WallMaterial(k=0.2, p=0.5, q=-0.5, name='glass "A" on steel')
    assert parse_config(config.to_toml()) == config
    assert config.sha256() != load_config().sha256()      # the wall law is part of the configuration's hash
    assert parse_config("[wall]\nk = 0.2\n").wall == WallMaterial(k=0.2, p=CORUNDUM_ON_STEEL.p,
                                                                   q=CORUNDUM_ON_STEEL.q, name=CORUNDUM_ON_STEEL.name)


def test_a_wall_preset_stands_for_its_section_and_takes_a_roughness():
    """``preset`` gives the preset file's [wall] section: the default wall's preset builds the default table (equal
    configuration text, so an equal hash); roughness_deg may be added; each preset file is a configuration alone,
    names itself and states where its law holds."""
    assert "corundum_on_St3_Lashkov1991" in wall_presets()
    default = parse_config('[wall]\npreset = "corundum_on_St3_Lashkov1991"\n')
    assert default == load_config() and default.sha256() == load_config().sha256()
    rough = parse_config('[wall]\npreset = "corundum_on_St3_Lashkov1991"\nroughness_deg = 5\n').wall
    assert rough == WallMaterial(roughness_deg=5.0, speed_range_m_s=(50.0, 300.0))
    for name in wall_presets():
        alone = parse_config(wall_preset_text(name), name)
        assert alone.wall.name == name and alone.wall.speed_range_stated
        assert parse_config(f'[wall]\npreset = "{name}"\n').wall == alone.wall


def test_the_wall_law_s_speed_range_and_the_grid_beyond_it():
    """The default law holds over 50-300 m/s; a law of one's own states none unless given; a given range round-trips;
    grid speeds outside it are one warning line (the build goes on)."""
    assert parse_config('[wall]\nname = "renamed"\n').wall.speed_range_m_s == (50.0, 300.0)
    assert not parse_config("[wall]\nq = 0.5\n").wall.speed_range_stated
    config = parse_config("[wall]\nk = 0.2\nspeed_range_m_s = [1, 30]\n")
    assert config.wall.speed_range_m_s == (1.0, 30.0) and parse_config(config.to_toml()) == config
    lines = []
    parse_config("[grid]\nspeed_m_s = [0.5, 5.0, 40.0]\n[wall]\nk = 0.2\nspeed_range_m_s = [1, 30]\n", "case.toml",
                 log=lines.append)
    assert lines == ["warning: case.toml: the grid's speeds 0.5, 40 m/s lie outside 1-30 m/s, where the wall law "
                     "'corundum_on_St3_Lashkov1991' holds (wall.speed_range_m_s); its cells apply the law there all "
                     "the same"]
    lines.clear()
    load_config(log=lines.append)
    assert lines == []


def test_range_grid_includes_stop_and_defaults_fill_in():
    config = parse_config("[grid]\nspeed_m_s = {start = 100, stop = 200, step = 50}\n")
    assert config.speed_m_s == (100.0, 150.0, 200.0)
    assert config.alpha1_deg == load_config().alpha1_deg


BAD = [
    ("[grid]\nalpha1_deg = []", "grid.alpha1_deg"),
    ("[grid]\nalpha1_deg = [0.0, 10.0]", "grid.alpha1_deg"),
    ("[grid]\nalpha1_deg = [45.0, 95.0]", "grid.alpha1_deg"),
    ("[grid]\nspeed_m_s = [0.0, 100.0]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [-50.0]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [200.0, 100.0]", "grid.speed_m_s"),
    # grids the runtime cannot serve: speeds outside [0.001, 10⁴] m/s or neighbours too far apart for its
    # restitution pieces
    ("[grid]\nspeed_m_s = [0.0001, 300.0]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [1e-300, 1e300]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [1e-300]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [20000.0]", "grid.speed_m_s"),
    ("[grid]\nspeed_m_s = [10.0, 200.0]", "grid.speed_m_s"),
    ("[grid]\nshapes = [\"sphere\"]", "grid.shapes"),
    ("[grid]\nshapes = []", "grid.shapes"),
    ("[simulation]\nparticles_per_cell = 0", "simulation.particles_per_cell"),
    ("[simulation]\nparticles_per_cell = -5", "simulation.particles_per_cell"),
    ("[simulation]\nn_max = 0", "simulation.n_max"),
    ("[simulation]\nkappa = 1.5", "simulation.kappa"),
    ("[simulation]\nparticle_count = 10", "simulation.particle_count"),
    ("[grids]\nalpha1_deg = [10.0]", "[grids]"),
    ("[table]\nresolution = {clusters = 0}", "table.resolution"),
    ("[table]\nresolution = {atoms = 8}", "table.resolution.atoms"),
    ("[wall]\nk = 0.0", "wall.k"),
    ("[wall]\np = -0.5", "wall.p"),
    ("[wall]\nq = nan", "wall.q"),
    ("[wall]\nk = true", "wall.k"),
    ("[wall]\nname = \"\"", "wall.name"),
    ("[wall]\nfriction = 1.0", "wall.friction"),
    ("[wall]\nspeed_range_m_s = [300.0, 50.0]", "wall.speed_range_m_s"),
    ("[wall]\nspeed_range_m_s = [50.0]", "wall.speed_range_m_s"),
    ("[wall]\nspeed_range_m_s = [-1.0, 50.0]", "wall.speed_range_m_s"),
    ("[wall]\nspeed_range_m_s = [1.0, inf]", "wall.speed_range_m_s"),
    ("[wall]\nspeed_range_m_s = \"fast\"", "wall.speed_range_m_s"),
    ("[wall]\nroughness_deg = -1.0", "wall.roughness_deg"),
    ("[wall]\nroughness_deg = 46", "wall.roughness_deg"),
    ("[wall]\nroughness_deg = nan", "wall.roughness_deg"),
    ("[wall]\nroughness_deg = true", "wall.roughness_deg"),
    ("[wall]\npreset = \"sand_on_Al\"", "wall.preset"),
    ("[wall]\npreset = 1", "wall.preset"),
    ("[wall]\npreset = \"corundum_on_St3_Lashkov1991\"\nq = 0.5", "wall.q"),
    ("[wall]\npreset = \"corundum_on_St3_Lashkov1991\"\nname = \"mine\"", "wall.name"),
    ("[wall]\npreset = \"corundum_on_St3_Lashkov1991\"\nroughness_deg = 50", "wall.roughness_deg"),
]


@pytest.mark.parametrize("text, key", BAD)
def test_bad_values_name_the_key(text, key):
    with pytest.raises(ConfigError, match=key.replace("[", r"\[").replace("]", r"\]")):
        parse_config(text)


@pytest.mark.parametrize("text, key", BAD)
def test_cli_exits_2_and_leaves_the_output_untouched(text, key, tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    out = tmp_path / "table.h5"
    out.write_bytes(b"previous content")
    line, _ = user_error(tablegen_main, ["build", "--config", str(cfg), "-o", str(out), "--overwrite"], capsys, key)
    assert line.startswith("tablegen build: error: ")
    assert out.read_bytes() == b"previous content"
    assert not (tmp_path / "table.h5.partial").exists()


@pytest.mark.parametrize("speeds, words", [
    ("[0.0001, 300.0]", ["[0.001, 10000] m/s", "0.0001"]),
    ("[1e-300]", ["[0.001, 10000] m/s", "1e-300"]),
    ("[10.0, 200.0]", ["10.0 and 200.0", "factor 20", "at most 16"]),
])
def test_speed_grids_the_runtime_cannot_serve_name_the_allowed_range(tmp_path, capsys, speeds, words):
    """One line, exit 2, the value and the allowed range; nothing built."""
    config = tmp_path / "c.toml"
    config.write_text(f"[grid]\nalpha1_deg = [45.0]\nspeed_m_s = {speeds}\nshapes = [\"prism\"]\n")
    code = tablegen_main(["build", "--config", str(config), "-o", str(tmp_path / "t.h5")])
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and len(err) == 1, err
    for word in words:
        assert word in err[0], err[0]
    assert not (tmp_path / "t.h5").exists()


def test_a_rough_wall_reads_and_round_trips_and_a_smooth_one_writes_no_roughness():
    """roughness_deg (degrees) is read with any law; a smooth wall's configuration text has no roughness line, so a
    smooth table's configuration, hash and fingerprint are those before rough walls."""
    config = parse_config("[wall]\nroughness_deg = 7.5\n")
    assert config.wall.roughness_deg == 7.5 and config.wall.speed_range_m_s == (50.0, 300.0)
    assert "roughness_deg = 7.5" in config.to_toml() and parse_config(config.to_toml()) == config
    assert "roughness" not in parse_config("").to_toml()
    assert parse_config("[wall]\nroughness_deg = 0\n").to_toml() == parse_config("").to_toml()


def test_a_tabulated_wall_law_reads_checks_and_round_trips():
    """law = "tabulated": q and the three arrays; its text round-trips (so the table's configuration rebuilds it);
    a key of another family, a missing array and a value outside (0, 1] are one error naming the key."""
    from direct_model.wall import TabulatedWall
    from tests.helpers.tables import TABULATED_WALL

    config = parse_config(TABULATED_WALL)
    assert config.wall == TabulatedWall((40.0, 120.0, 300.0), (0.0, 0.5, 1.0),
                                        ((1.0, 0.8, 0.55), (1.0, 0.75, 0.5), (1.0, 0.7, 0.42)), 0.8,
                                        name="test_tabulated")
    assert not config.wall.speed_range_stated and parse_config(config.to_toml()) == config
    assert 'law = "tabulated"' in config.to_toml() and "k = " not in config.to_toml()
    for edit, word in [
        (TABULATED_WALL + "k = 0.2\n", "'wall.k' is not a parameter of the tabulated wall law"),
        (TABULATED_WALL.replace("contact_sine = [0.0, 0.5, 1.0]\n", ""), "needs 'wall.contact_sine'"),
        (TABULATED_WALL.replace("0.42", "1.2"),
         r"'restitution' must be in \(0, 1\] at every node; got 1.2 at \[2\]\[2\]"),
        (TABULATED_WALL.replace("[0.0, 0.5, 1.0]", "[0.0, 0.5, 0.9]"), "'contact_sine' must be 2 to 16"),
        (TABULATED_WALL.replace("[40.0, 120.0, 300.0]", "[40.0, true, 300.0]"),
         "'wall.contact_speed_m_s' must be a list"),
        (TABULATED_WALL.replace('"tabulated"', '"linear"'), "'wall.law' must be one of exponential, tabulated"),
    ]:
        with pytest.raises(ConfigError, match=word):
            parse_config(edit, "case.toml")


def test_the_default_configuration_text_is_unchanged_by_the_law_families():
    """The exponential law's [wall] lines are what they were before the families (k, p, q, name, range), so the
    default table's configuration, its hash and its fingerprint stay those of 1.0."""
    text = load_config().to_toml()
    assert text.split("[wall]\n")[1].strip() == (
        "k = 0.1\np = 0.61\nq = 1.0\nname = \"corundum_on_St3_Lashkov1991\"\nspeed_range_m_s = [50.0, 300.0]")
