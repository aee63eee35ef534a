-- A hand-built chain hanging between two pins: its sag and the pull on each support
-- against the catenary. Built as a user would: w:particle along the straight line between
-- the pins, w:distance links given a rest length longer than that (the chain's length),
-- default radius and contacts, default substeps.
local D, L, N = 1.0, 1.2, 60          -- span, chain length, links: 2 cm per link
local M = 0.6                          -- chain mass (kg), spread over the N - 1 free particles
local Y0, g = 1.5, 9.81

-- continuous catenary y = a cosh(x/a): L = 2 a sinh(D / 2a); solve for a by bisection
local function catenary()
  local lo, hi = 1e-3, 100
  for _ = 1, 200 do
    local a = 0.5 * (lo + hi)
    if 2 * a * math.sinh(D / (2 * a)) > L then lo = a else hi = a end
  end
  local a = 0.5 * (lo + hi)
  return a, a * (math.cosh(D / (2 * a)) - 1)
end
local a, sag = catenary()
local wlen = M * g / L                           -- weight per unit length (N/m)
local H = wlen * a                               -- horizontal tension
local T_support = wlen * (a + sag)               -- |T| at a support = w y(D/2)

local function build()
  -- damping: a drag (1/s) so that the chain comes to rest within the run; a user wanting
  -- the static shape would add it. A drag changes no static equilibrium.
  -- 40 substeps: rigid links converge only with enough of them (docs/physics.md, "Convergence");
  -- at the default 10 x 1 this chain settles 11.7% too low
  local w = wobble.world{ damping = 2, substeps = 40 }
  local ids, links = {}, {}
  for i = 0, N do
    ids[#ids + 1] = w:particle{ pos = { -D / 2 + D * i / N, Y0, 0 }, mass = (i == 0 or i == N) and 0 or M / (N - 1) }
  end
  -- mass 0 = immovable: the two supports
  for i = 1, N do links[i] = w:distance(ids[i], ids[i + 1], { rest = L / N }) end
  return w, ids, links
end

test("hand-built chain between two pins: sag and support force match the catenary", function()
  local w, ids, links = build()
  w:run{ seconds = 6 }
  local lowest = math.huge
  for _, p in ipairs(ids) do local _, y = w:position(p); lowest = math.min(lowest, y) end
  local measured_sag = Y0 - lowest
  local f_left, f_right = links[1]:force(), links[N]:force()
  local len = 0
  for _, c in ipairs(links) do len = len + c:length() end
  local ke = w:energy()
  print(string.format("catenary a = %.4f m: sag %.4f m expected, %.4f measured; support force %.4f N expected, "
    .. "left %.4f right %.4f measured; chain length %.4f (rest %.2f); kinetic %.2e J; max strain %.4f",
    a, sag, measured_sag, T_support, f_left, f_right, len, L, ke, w:max_strain()))
  -- discrete vs continuous chain of 60 links: the lumped-mass chain's sag differs by
  -- O(1/N^2) (< 0.1%); 2% allows the solver's residual stretch of rigid links
  expect.rel(measured_sag, sag, 0.02, "sag")
  -- the end link's tension: the support force, same O(1/N) discretisation (the end
  -- link's slope differs from the catenary's end slope by half a link: ~1%); 3%
  expect.rel(f_left, T_support, 0.03, "left support force")
  expect.rel(f_right, T_support, 0.03, "right support force")
  expect.lt(ke, 1e-4, "at rest")
  expect.rel(len, L, 0.02, "rigid links keep the chain's length")
end)

test("hand-built chain: the vertical support forces carry the chain's weight", function()
  local w, ids, links = build()
  w:run{ seconds = 6 }
  local function fy(c, pin)
    local p, q = c:particles()
    local other = (p == pin) and q or p
    local x1, y1 = w:position(pin)
    local x2, y2 = w:position(other)
    local dx, dy = x2 - x1, y2 - y1
    return c:force() * math.abs(dy) / math.sqrt(dx * dx + dy * dy), c:force() * math.abs(dx) / math.sqrt(dx * dx + dy * dy)
  end
  local vl, hl = fy(links[1], ids[1])
  local vr, hr = fy(links[N], ids[N + 1])
  print(string.format("vertical: %.4f + %.4f = %.4f N (weight %.4f); horizontal %.4f / %.4f (catenary H %.4f)",
    vl, vr, vl + vr, M * g, hl, hr, H))
  -- static equilibrium (exact for any discretisation): the supports carry the weight
  expect.rel(vl + vr, M * g, 0.01, "vertical support forces sum to the weight")
  expect.rel(hl, H, 0.03, "horizontal tension = w a")
end)
