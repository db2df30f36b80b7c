"""Named corner cases of the testbench; each must be reached at least once."""


class Coverage:
    def __init__(self, required):
        self.required = list(required)
        self.hits = {name: 0 for name in self.required}

    def hit(self, name, condition=True):
        assert name in self.hits, f"unknown coverage point {name}"
        if condition:
            self.hits[name] += 1

    def missed(self):
        return [n for n in self.required if self.hits[n] == 0]

    def report(self) -> str:
        return "\n".join(f"  {n:40s} {self.hits[n]}" for n in self.required)
