"""Python controllers: called each tick with the robot's observation, returning (v, w)."""

import pytest

import sim
from conftest import verify_rrd


def test_a_python_controller_drives_its_robot():
    seen = []

    def spin(obs):
        seen.append((obs.tick, obs.time, obs.dt))
        assert obs.robot.name == "scout"
        assert obs.robot.ranges is None or len(obs.robot.ranges) > 0
        return (0.0, 0.8)

    s = sim.Simulation("maze_run", threads=1, controllers={"scout": spin})
    s.run_for(1.0)
    assert [t for t, _, _ in seen] == list(range(20))
    assert seen[3][1] == pytest.approx(0.15) and seen[0][2] == pytest.approx(0.05)
    assert s.robot("scout").twist[1] == pytest.approx(0.8, abs=0.05)


def test_an_observation_is_valid_during_its_call_only():
    kept = []

    def keep(obs):
        kept.append(obs)
        return (0.1, 0.0)

    s = sim.Simulation("maze_run", threads=1, controllers={"scout": keep})
    s.step()
    with pytest.raises(RuntimeError, match="during its controller's call"):
        kept[0].robot.pose


def test_a_controller_that_raises_ends_the_run_and_the_recording_is_finished(tmp_path):
    class Boom(Exception):
        pass

    def fail_at_ten(obs):
        if obs.tick == 10:
            raise Boom("wheel fell off")
        return (0.3, 0.0)

    rrd = tmp_path / "boom.rrd"
    s = sim.Simulation("maze_run", threads=1, rrd=rrd, controllers={"scout": fail_at_ten})
    with pytest.raises(Boom, match="wheel fell off"):
        s.run_for(2.0)
    assert s.finished
    assert s.summary["robots"][0]["name"] == "scout"
    verify_rrd(rrd)


def test_a_controller_returning_garbage_is_a_clear_error():
    s = sim.Simulation("maze_run", threads=1, controllers={"scout": lambda obs: "fast"})
    with pytest.raises(TypeError, match="controller of `scout` returned 'fast'"):
        s.step()
    s2 = sim.Simulation("maze_run", threads=1, controllers={"scout": lambda obs: (float("nan"), 0)})
    with pytest.raises(ValueError, match="finite"):
        s2.step()


def test_controllers_for_unknown_robots_and_non_callables_are_refused():
    with pytest.raises(sim.ScenarioError, match="ghost"):
        sim.Simulation("maze_run", controllers={"ghost": lambda o: (0, 0)})
    with pytest.raises(ValueError, match="callable"):
        sim.Simulation("maze_run", controllers={"scout": 3})


def test_a_controller_reading_the_simulation_mid_step_gets_an_error():
    holder = {}

    def peek(obs):
        holder["s"].robot("scout").pose
        return (0.0, 0.0)

    s = sim.Simulation("maze_run", threads=1, controllers={"scout": peek})
    holder["s"] = s
    with pytest.raises(sim.SimError, match="busy"):
        s.step()
