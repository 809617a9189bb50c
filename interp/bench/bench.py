"""The compute benchmark of bench.src, hand-written in Python (the host-language figure
of `krl bench`). Same algorithms, same operation order, same results."""

from __future__ import annotations


def sieve(n: int) -> int:
    comp = [False] * (n + 1)
    count = 0
    for i in range(2, n + 1):
        if not comp[i]:
            count += 1
            j = i * i
            while j <= n:
                comp[j] = True
                j += i
    return count


def sorted_check(n: int, seed: int) -> int:
    a = [0] * (n + 1)
    for i in range(1, n + 1):
        seed = seed * 1103 + 12345
        seed = seed - (seed // 65536) * 65536
        a[i] = seed
    for i in range(2, n + 1):
        key = a[i]
        j = i - 1
        while j >= 1 and a[j] > key:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = key
    return sum(a[i] // 16 for i in range(1, n + 1, 7))


def matmul(n: int) -> float:
    a = [[(i + j) * 0.5 for j in range(n + 1)] for i in range(n + 1)]
    b = [[(i - j) * 0.25 + 1.0 for j in range(n + 1)] for i in range(n + 1)]
    c = [[0.0] * (n + 1) for _ in range(n + 1)]
    for i in range(1, n + 1):
        for j in range(1, n + 1):
            s = 0.0
            for k in range(1, n + 1):
                s = s + a[i][k] * b[k][j]
            c[i][j] = s
    s = 0.0
    for i in range(1, n + 1):
        s = s + c[i][i]
    return s


class Vec3:
    __slots__ = ("x", "y", "z")

    def __init__(self, x: float, y: float, z: float) -> None:
        self.x, self.y, self.z = x, y, z


def move3(p: Vec3, v: Vec3, dt: float) -> None:
    v.z = v.z - 9.81 * dt
    p.x = p.x + v.x * dt
    p.y = p.y + v.y * dt
    p.z = p.z + v.z * dt
    if p.z < 0.0:
        p.z = -p.z
        v.z = -v.z * 0.9


def dot3(a: Vec3, b: Vec3) -> float:
    return a.x * b.x + a.y * b.y + a.z * b.z


def particles(n: int) -> float:
    p = Vec3(0.0, 0.0, 1.0)
    v = Vec3(1.0, 0.5, 0.0)
    e = 0.0
    for _ in range(n):
        move3(p, v, 0.01)
        e = e + dot3(Vec3(v.x, v.y, v.z), Vec3(v.x, v.y, v.z))   # :IN copies, as KRL
    return e + p.x + p.y + p.z


def bench(rounds: int = 2) -> tuple[int, float]:
    check_i = 0
    check_r = 0.0
    for r in range(1, rounds + 1):
        check_i += sieve(1500)
        check_i += sorted_check(120, r)
        check_r += matmul(10)
        check_r += particles(150)
    return check_i, check_r


if __name__ == "__main__":
    print(bench())
