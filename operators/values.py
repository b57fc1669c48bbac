"""Property values as the user typed them."""
import numpy as np


def typed(value: float) -> float:
    """Blender keeps FloatProperty values as float32; the shortest decimal that rounds to
    the same float32 is what the user typed (0.09016, not 0.09015999734401703)."""
    return float(str(np.float32(value)))
