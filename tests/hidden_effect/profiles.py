"""Motion profiles of the hidden-effect matrix, and what the tools must say they cover.

A profile is the text both generators take (`rpm[-rpm_end]:seconds,...`; 0 = hold,
negative = backwards, `a-b:s` a linear ramp) and the resolver pole pairs p_r. From the
text alone we derive what `resolver-model explain` must report in `covers`: the
mechanical revolutions travelled (the integral of |omega|, never the net angle) and the
reversals (sign changes of the speed, through a hold, a ramp or a step).
"""
import re
from dataclasses import dataclass

_ITEM = re.compile(r"^(-?\d+(?:\.\d+)?)(?:-(-?\d+(?:\.\d+)?))?:(\d+(?:\.\d+)?)$")


@dataclass(frozen=True)
class Profile:
    name: str
    text: str
    p_r: int
    why: str
    # Analyse with a resolverd config whose signal map holds only rd_angle and ref_angle
    # (issue 13's scope export: no sin/cos, no currents).
    angle_only: bool = False

    def segments(self):
        """(rpm_start, rpm_end, seconds) per item."""
        out = []
        for item in self.text.split(","):
            m = _ITEM.match(item.strip())
            if not m:
                raise ValueError(f"profile {self.name}: cannot parse item '{item}'")
            a = float(m.group(1))
            b = float(m.group(2)) if m.group(2) is not None else a
            out.append((a, b, float(m.group(3))))
        return out

    def travelled_revolutions(self):
        """Mechanical revolutions travelled, the integral of |omega| dt."""
        rev = 0.0
        for a, b, s in self.segments():
            if a * b >= 0:
                rev += abs(a + b) / 2 * s / 60
            else:  # a ramp through zero: two triangles
                rev += (a * a + b * b) / (2 * abs(a - b)) * s / 60
        return rev

    def reversals(self):
        """Sign changes of the speed over the whole profile (holds do not reset the sign)."""
        signs = []
        for a, b, _ in self.segments():
            for v in (a, b):
                if v != 0:
                    signs.append(v > 0)
        return sum(1 for x, y in zip(signs, signs[1:]) if x != y)

    def hold_seconds(self):
        return sum(s for a, b, s in self.segments() if a == 0 and b == 0)

    def holds(self):
        return sum(1 for a, b, _ in self.segments() if a == 0 and b == 0)

    def zero_crossings(self):
        """Passes through zero speed without a hold: a ramp through zero or a step reversal."""
        n = sum(1 for a, b, _ in self.segments() if a * b < 0)
        segs = self.segments()
        return n + sum(1 for (_, b, _), (c, _, _) in zip(segs, segs[1:]) if b * c < 0)


# Short logs (the matrix runs ~200 cases): 3 mechanical revolutions each way, 0.5 s
# holds (1000 standstill samples each for the noise floor).
OUT_AND_BACK = "0:0.5,120:1.5,0:0.5,-120:1.5,0:0.5"
PROFILES = {p.name: p for p in [
    Profile("const", "200:3", 3, "the default bench: constant 200 r/min"),
    Profile("oab3", OUT_AND_BACK, 3, "out and back with standstills, p_r = 3"),
    Profile("oab1", OUT_AND_BACK, 1, "out and back with standstills, a 1X resolver"),
    Profile("steps", "100:1.5,300:1.5,600:1.5", 3, "speed steps"),
    Profile("ramps", "0:0.25,0-600:1.5,600:0.5,600-0:1.5,0:0.25", 3, "ramps from and to standstill"),
    Profile("reversals", "120:1,120--120:0.5,-120:1,-120-120:0.5,120:1,60:0.5,-60:0.5", 3,
            "reversals through ramps and one step reversal"),
    # The tracking loop needs a wide speed range (its filtering grows with speed) and
    # ramps, not steps: a step kicks a type-II loop into a transient.
    Profile("loop_ramp", "500:1,500-2000:2,2000:1", 3, "a ramp from 500 to 2000 r/min"),
    Profile("angle1", OUT_AND_BACK, 1,
            "out and back, p_r = 1, analysed with a signal map of only rd_angle and ref_angle",
            angle_only=True),
]}
# TODO(issue 13, input branch): the angle-only layout WITHOUT a counter (benchgen
# --layout angle_only, 0x200, degrees) and DBC units in degrees/rev (benchgen --layout
# be_counter), the scope CSV (FILETIME, degrees) and the ASC log: add them as profiles
# here once resolver-model reads them (the input helper's branch).
