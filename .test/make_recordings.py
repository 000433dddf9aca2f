"""Write the test configuration's two SIMULATED recordings (.test/data/): the paper's tanh
device shaken for 8 s, two seeds, each with its sidecar (M, m, k, filtered_at_hz).

    .venv/bin/python .test/make_recordings.py
"""

from pathlib import Path

from harvester.synthetic.measured import write_example_recording

HERE = Path(__file__).resolve().parent

if __name__ == "__main__":
    write_example_recording(HERE / "data/shaker_a.csv", duration_s=8.0, seed=101)
    write_example_recording(HERE / "data/shaker_b.csv", duration_s=8.0, seed=102)
