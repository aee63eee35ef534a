-- export_vtk.lua: VTK series for ParaView (w:record_vtk: a .pvd collection and a .vtp
-- per frame) and single frames (w:save_vtp): points = particles with velocity, speed,
-- strain, mass and pinned; cells = vertices, constraint lines and surface triangles.

local function read(name)
  local f = assert(io.open(name, "rb"))
  local s = f:read("a")
  f:close()
  return s
end

-- the numbers of the DataArray called `name` in a .vtp
local function array(vtp, name)
  local body = vtp:match('Name="' .. name .. '"[^>]*>(.-)</DataArray>')
  assert(body, "no array " .. name)
  local t = {}
  for x in body:gmatch("%S+") do t[#t + 1] = tonumber(x) end
  return t
end

test("a series: one .vtp per frame, listed with its time in the .pvd", function()
  local w = wobble.world{}
  local cloth = w:cloth{ origin = {0, 1, 0}, size = {1, 1}, res = {4, 4} }
  cloth:pin_where(function(x, y, z) return z == 0 end)
  local rec = assert(w:record_vtk("export_vtk/sim"))
  w:run{ frames = 6 }
  expect.eq(rec:frames(), 7)
  expect.eq(rec:close(), true)
  local pvd = read("export_vtk/sim.pvd")
  expect.truthy(pvd:find('<VTKFile type="Collection"', 1, true))
  expect.truthy(pvd:find("</Collection>\n</VTKFile>\n$"), "closed")
  local n = 0
  for t, file in pvd:gmatch('<DataSet timestep="(%S+)" group="" part="0" file="(%S+)"/>') do
    expect.near(tonumber(t), n / 60, 1e-12)
    expect.eq(file, string.format("sim/frame_%06d.vtp", n))
    n = n + 1
  end
  expect.eq(n, 7)
  -- the last frame's fields are the world's now
  local vtp = read("export_vtk/sim/frame_000006.vtp")
  expect.truthy(vtp:find('NumberOfPoints="16" NumberOfVerts="16" NumberOfLines="33" NumberOfStrips="0" NumberOfPolys="18"', 1, true))
  local pos, vel, speed = array(vtp, "position"), array(vtp, "velocity"), array(vtp, "speed")
  local strain, pinned, mass = array(vtp, "strain"), array(vtp, "pinned"), array(vtp, "mass")
  expect.eq(#pos, 48)
  for p = 1, 16 do
    local x, y, z = w:position(p)
    local vx, vy, vz = w:velocity(p)
    expect.near(pos[3 * p - 2], x, 1e-8); expect.near(pos[3 * p - 1], y, 1e-8); expect.near(pos[3 * p], z, 1e-8)
    expect.near(vel[3 * p - 1], vy, 1e-8 * (1 + math.abs(vy)))
    expect.near(speed[p], math.sqrt(vx * vx + vy * vy + vz * vz), 1e-8)
    expect.eq(pinned[p], w:pinned(p) and 1 or 0)
    expect.near(mass[p], w:mass(p), 1e-12)
    expect.ge(strain[p], 0)
  end
  local worst = 0
  for _, e in ipairs(strain) do worst = math.max(worst, e) end
  expect.near(worst, w:max_strain(), 1e-8)
  -- cells: lines are pairs, polygons triangles, offsets running
  local lines = array(vtp:match("<Lines>(.-)</Lines>"), "connectivity")
  expect.eq(#lines, 66)
  local offs = array(vtp:match("<Polys>(.-)</Polys>"), "offsets")
  expect.eq(offs[#offs], 54)
end)

test("the .pvd's times are frame x dt, exactly (a running sum of dt drifts)", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 1, 0} }
  local rec = assert(w:record_vtk("export_vtk/times"))
  w:run{ frames = 30 }
  rec:close()
  local n = 0
  for t in read("export_vtk/times.pvd"):gmatch('timestep="(%S+)"') do
    expect.eq(tonumber(t), n * (1 / 60), "frame " .. n)
    n = n + 1
  end
  expect.eq(n, 31)
  -- ParaView shows the frame whose time is 0.5 s for 0.5 s (a sum made it 0.49999999999999994)
  expect.truthy(read("export_vtk/times.pvd"):find('timestep="0.5" group="" part="0" file="times/frame_000030.vtp"', 1, true))
end)

test("every = k and a single frame", function()
  local w = wobble.world{}
  w:rope{ from = {0, 1, 0}, to = {1, 1, 0}, segments = 3 }
  local rec = w:record_vtk("export_vtk/every.pvd", { every = 4 })
  w:run{ frames = 9 }
  expect.eq(rec:frames(), 3)
  rec:close()
  expect.truthy(read("export_vtk/every/frame_000008.vtp"))
  expect.eq(w:save_vtp("export_vtk/one.vtp"), true)
  local vtp = read("export_vtk/one.vtp")
  expect.truthy(vtp:find('NumberOfPoints="4" NumberOfVerts="4" NumberOfLines="3"', 1, true))
  expect.truthy(vtp:find("</VTKFile>\n$"))
end)

test("bad arguments", function()
  local w = wobble.world{}
  expect.error(function() w:record_vtk("export_vtk/x", { every = -1 }) end, "out of range")
  expect.error(function() w:record_vtk("export_vtk/x", { fps = 1 }) end, "unknown key 'fps'")
  expect.error(function() w:record_vtk("/tmp/wobble-never") end, "is outside the output folder")
  local ok, err = w:save_vtp("export_vtk")
  expect.eq(ok, nil)
  expect.truthy(err:find("^export_vtk: "), err)
end)

test("the .pvd stays valid XML for names with & < > \" '", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 1, 0} }
  local rec = assert(w:record_vtk([[export_vtk/a&b<c>d"e'f]]))
  w:run{ frames = 1 }
  rec:close()
  local pvd = read([[export_vtk/a&b<c>d"e'f.pvd]])
  local files = {}
  for file in pvd:gmatch('file="([^"]*)"') do files[#files + 1] = file end
  expect.eq(#files, 2)
  expect.eq(files[1], "a&amp;b&lt;c&gt;d&quot;e&apos;f/frame_000000.vtp")
  expect.eq(pvd:find("a&b", 1, true), nil)
  expect.eq(pvd:find("b<c", 1, true), nil)
  -- the frames are where the (unescaped) name says
  expect.truthy(read([[export_vtk/a&b<c>d"e'f/frame_000001.vtp]]):find("<VTKFile", 1, true))
end)
