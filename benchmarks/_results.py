"""Where benchmark scripts put their output: printed, and saved under benchmarks/results/."""
import pathlib

RESULTS = pathlib.Path(__file__).parent / "results"


def publish(name, lines):
    """Print the report ``lines`` and write them to benchmarks/results/``name``."""
    text = "\n".join(lines)
    print(text)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / name).write_text(text + "\n")
