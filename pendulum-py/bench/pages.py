"""Why large results are kept in huge pages (`pendulum-py/src/results.rs`), in one run:

    target/python/bin/python pendulum-py/bench/pages.py

Writes 576 MB (the Jacobians of 10⁴ 3D states of 20 links) once into a numpy array
(numpy asks the kernel for huge pages on arrays of 4 MB and more) and once into an
anonymous memory map of plain 4 kB pages, one thread, best of three each. Where the
machine's transparent huge pages are "never", both read alike.
"""

import mmap
import timeit

import numpy as np

size = 576_000_000


def numpy_pages():
    np.ones(size // 8)


def plain_pages():
    m = mmap.mmap(-1, size)
    x = np.frombuffer(m, dtype=np.float64)
    x[:] = 1.0
    del x
    m.close()


try:
    with open("/sys/kernel/mm/transparent_hugepage/enabled") as f:
        print(f"transparent huge pages: {f.read().strip()}")
except OSError:
    print("transparent huge pages: not Linux, or not told")
for name, f in [("numpy's array (huge pages asked)", numpy_pages), ("plain 4 kB pages", plain_pages)]:
    print(f"writing 576 MB into {name}: {min(timeit.repeat(f, number=1, repeat=3)) * 1e3:.0f} ms")
