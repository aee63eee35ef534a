-- A w:cloth (the builder, its defaults: rigid links, default radius, contacts on, 10
-- substeps) laid horizontal and pinned at the two corners of one edge, let go to hang.
-- Physics: pins do no work and the cloth's links only store or lose energy, so the total
-- energy (kinetic + gravity + elastic) may only fall; it hangs below the pins; rigid
-- links barely stretch. The manual gives no strain figure for a default cloth; it says
-- compliance 0 is rigid, so 5% (the order of what the examples print for their cloths,
-- e.g. the clothesline's few %) is the bound a user would expect.
local S, RES, Y0, M = 1.0, 21, 1.5, 0.5
local g = 9.81

local function build(damping)
  -- 40 substeps: rigid links converge only with enough of them (docs/physics.md, "Convergence");
  -- at the default 10 x 1 this cloth stretches 40% while it swings, 12% at rest
  local w = wobble.world{ damping = damping, substeps = 40 }
  local c = w:cloth{ origin = { -S / 2, Y0, -S / 2 }, size = { S, S }, res = { RES, RES }, mass = M }
  local pins = c:pin_where(function(x, y, z) return z < -S / 2 + 1e-6 and math.abs(math.abs(x) - S / 2) < 1e-6 end)
  return w, c, pins
end

test("w:cloth pinned at two corners swinging: no energy gained, links barely stretched", function()
  local w, c, pins = build()
  expect.eq(pins, 2, "two corners pinned")
  local ke0, pe0 = w:energy()
  local e0, emax, worst, above = ke0 + pe0, -math.huge, 0, -math.huge
  local e_prev, rises = e0, 0
  w:run{ seconds = 5, on_frame = function(w, f, t)
    local ke, pe = w:energy()
    emax = math.max(emax, ke + pe)
    if ke + pe > e_prev + 1e-6 then rises = rises + 1 end
    e_prev = ke + pe
    if t > 1 then worst = math.max(worst, w:max_strain()) end
    local _, _, _, _, maxy = w:bounds()
    if t > 1 then above = math.max(above, maxy) end
  end }
  local ke, pe = w:energy()
  local sy = 0
  for _, p in ipairs(c.particles) do local _, y = w:position(p); sy = sy + y end
  local com_y = sy / #c.particles
  print(string.format("energy start %.4f J, max %.4f J, end %.4f J (kinetic %.4f); frames where it rose: %d; "
    .. "max strain after 1 s %.4f; highest point after 1 s %.4f (pins at %.2f); COM y %.3f; warnings %d",
    e0, emax, ke + pe, ke, rises, worst, above, Y0, com_y, (w:warnings())))
  -- no work is done on the cloth: its energy may not exceed the start by more than
  -- round-off (1e-3 of the energy scale M g S)
  expect.le(emax, e0 + 1e-3 * M * g * S, "total energy never above its start")
  -- swinging without drag it keeps swinging (a particle may whip above its start, so
  -- no height bound here); its links are rigid: a few % at most
  expect.lt(worst, 0.05, "max strain (rigid links) after the first second")
end)

test("w:cloth pinned at two corners comes to hang at rest below the pins, links barely stretched", function()
  -- damping 1/s: a drag, so that it comes to rest in the run (a user who wants the
  -- hanging shape adds it); it changes no static equilibrium
  local w, c = build(1)
  w:run{ seconds = 6 }
  local ke = w:energy()
  local _, _, _, _, maxy = w:bounds()
  local sy = 0
  for _, p in ipairs(c.particles) do local _, y = w:position(p); sy = sy + y end
  local com_y = sy / #c.particles
  print(string.format("at rest: kinetic %.2e J, highest point %.4f (pins %.2f), COM y %.3f, max strain %.4f",
    ke, maxy, Y0, com_y, w:max_strain()))
  expect.lt(ke, 0.02, "nearly at rest")
  expect.le(maxy, Y0 + 1e-3, "hangs below the pins")
  -- a square hanging by two corners: its COM about S/2 below them (a rigid sheet's
  -- would be S/2; the sag between the pins lowers it): at least 0.4 S
  expect.lt(com_y, Y0 - 0.4 * S, "COM well below the pins")
  -- static: the corner links carry half the weight each (M g / 2 = 2.5 N); rigid links
  expect.lt(w:max_strain(), 0.05, "max strain at rest")
end)
