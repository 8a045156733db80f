# A tiny deterministic generator that gives the same numbers under CPython and MicroPython.


class Lcg:
    def __init__(self, seed):
        self.state = seed & 0x7FFFFFFF

    def next(self):
        self.state = (1103515245 * self.state + 12345) & 0x7FFFFFFF
        return self.state

    def below(self, n):
        return self.next() % n

    def bytes(self, n):
        return bytes([self.next() >> 16 & 0xFF for _ in range(n)])
