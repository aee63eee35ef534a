-- json_errors.lua: a bad particle config is nil and "file:line:col: key.path: reason",
-- and the world is left exactly as it was. Positions are 1-based lines and columns of
-- the offending value (or key, for key errors); key paths index arrays from 0, as the
-- file's own indices do.

local NAME = "json_errors/bad.json"

local function write(name, text)
  local f = assert(io.open(name, "wb"))
  f:write(text)
  f:close()
  return name
end

-- a world with something in it; loading `text` must fail with `expected` (a plain
-- substring) and change nothing
local function bad(text, expected)
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  w:particle{ pos = {1, 0, 0} }
  w:distance(1, 2)
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local hash = w:hash()
  local b, err = w:load_particles(write(NAME, text))
  expect.eq(b, nil, expected)
  expect.eq(type(err), "string")
  if type(err) == "string" then expect.truthy(err:find(expected, 1, true), "got: " .. err) end
  expect.eq(w:particle_count(), 2)
  expect.eq(w:stats().distances, 1)
  expect.eq(w:stats().colliders, 1)
  expect.eq(w:hash(), hash)
  return err
end

local HEAD = '{"format": "wobble-particles", "version": 1,\n'

-- "line:col" of the first occurrence of needle in text (after the init-th byte)
local function at(text, needle, init)
  local i = assert(text:find(needle, init or 1, true), needle)
  local line, col = 1, 1
  for k = 1, i - 1 do
    if text:sub(k, k) == "\n" then line, col = line + 1, 1 else col = col + 1 end
  end
  return NAME .. ":" .. line .. ":" .. col .. ": "
end

-- bad() where the message must start with the position of needle
local function bad_at(text, needle, message, init)
  return bad(text, at(text, needle, init) .. message)
end

test("syntax errors: cJSON's error position as line and column", function()
  bad('{"format": "wobble-particles",\n "version": 1,\n "particles": [,]}', NAME .. ":3:16: JSON syntax error near ',]}'")
  bad(HEAD .. ' "particles": [\n', NAME .. ":3:1: JSON syntax error: unexpected end of file")
  bad(HEAD .. ' "particles": []\n} trailing', NAME .. ":3:3: JSON syntax error near 'trailing'")
  bad(HEAD .. " 'particles': []}", NAME .. ":2:3: JSON syntax error near 'particles'") -- cJSON points past the quote
  -- deeper than cJSON's limit (1000): said so, at the bracket where it gave up
  local deep = HEAD .. ' "description": ' .. string.rep("[", 1200) .. string.rep("]", 1200) .. ', "particles": []}'
  local err = bad(deep, "JSON nested too deeply (more than 1000 levels of arrays and objects)")
  expect.truthy(err:find(NAME .. ":2:", 1, true), err)
  -- brackets inside strings do not count; a plain syntax error stays one
  bad(HEAD .. ' "description": "' .. string.rep("[", 1200) .. '", "particles": [,]}', "JSON syntax error near ',]}'")
  bad(HEAD .. ' "description": ' .. string.rep("[", 10) .. ',' .. string.rep("]", 10) .. ', "particles": []}', "JSON syntax error near")
  bad("  \n\t\n", NAME .. ": empty file")
  bad(HEAD .. ' "particles": []}\0', NAME .. ":2:18: not a text file (a NUL byte)")
end)

test("the top level: an object with format and version", function()
  bad("[1, 2]", NAME .. ":1:1: a particle config is a JSON object, got array")
  bad('{"version": 1, "particles": []}', NAME .. ":1:1: missing key 'format'")
  bad('{"format": "wobble-scene", "version": 1, "particles": []}',
      NAME .. ":1:12: format: 'wobble-scene' is not a particle config (expected 'wobble-particles')")
  local v2 = '{"format": "wobble-particles", "version": 2, "particles": []}'
  bad_at(v2, "2,", "version: version 2 is not supported (this wobble reads version 1)")
  bad('{"format": "wobble-particles", "version": "1", "particles": []}', "version: integer expected, got string")
  bad('{"format": "wobble-particles", "version": 1}', NAME .. ":1:1: missing key 'particles'")
end)

test("unknown, miscased and repeated keys are pointed at", function()
  bad(HEAD .. ' "particle": []}', NAME .. ":2:2: particle: unknown key 'particle' (expected one of: format, version, "
      .. "description, defaults, particles, constraints, colliders, surfaces, parts, skins, snapshot, rigids, volumes, tets, shape_matches, pressures, attachments, grabs, tethers)")
  bad(HEAD .. ' "Particles": []}', NAME .. ":2:2: Particles: unknown key 'Particles' (keys are case-sensitive: 'particles')")
  local t = HEAD .. ' "particles": [],\n "version": 1}'
  bad_at(t, '"version"', "version: duplicate key 'version' (first at line 1, column 32)", 40)
  bad(HEAD .. ' "particles": [{"position": [0,0,0], "position": [1,1,1]}]}', "particles[0].position: duplicate key 'position'")
  local t = HEAD .. ' "particles": [{"position": [0,0,0], "colour": 1}]}'
  bad_at(t, '"colour"', "particles[0].colour: unknown key 'colour' (expected one of: position, velocity, mass, inv_mass, radius, pinned, group, friction, collide, self_collide, created_at)")
end)

test("particles: types, shapes and ranges", function()
  local t = HEAD .. ' "particles": [{"position": [0,0,0]},\n  {"position": [1,0,0], "mass": "heavy"}]}'
  bad_at(t, '"heavy"', "particles[1].mass: number expected, got string")
  t = HEAD .. ' "particles": [{"position": [0,0]}]}'
  bad_at(t, "[0,0]", "particles[0].position: array of 3 numbers expected, got 2 values")
  t = HEAD .. ' "particles": [{"position": [0,0,"x"]}]}'
  bad_at(t, '"x"', "particles[0].position[2]: number expected, got string")
  t = HEAD .. ' "particles": [{"mass": 1}]}'
  bad_at(t, '{"mass"', "particles[0]: missing key 'position'")
  bad(HEAD .. ' "particles": [{"position": [0,0,0], "mass": -1}]}', "particles[0].mass: must be >= 0")
  bad(HEAD .. ' "particles": [{"position": [0,0,1e999]}]}', "particles[0].position[2]: number out of range")
  bad(HEAD .. ' "particles": [{"position": [0,0,0], "pinned": "yes"}]}', "particles[0].pinned: true or false expected, got string")
  t = HEAD .. ' "particles": [[0,0,0]]}'
  bad_at(t, "[0,0,0]", "particles[0]: object expected, got array")
  bad(HEAD .. ' "particles": {}}', "particles: array expected, got object")
  bad(HEAD .. ' "defaults": {"mass": null}, "particles": []}', "defaults.mass: number expected, got null")
end)

local TWO = HEAD .. ' "particles": [{"position": [0,0,0]}, {"position": [1,0,0]}],\n'

test("constraints: type, particles, options", function()
  local t = TWO .. ' "constraints": [{"type": "distance", "particles": [0, 5]}]}'
  bad_at(t, "5]", "constraints[0].particles[1]: 5 out of range (0..1)")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [1, 1]}]}', "constraints[0].particles: a constraint needs two distinct particles")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1.5]}]}', "constraints[0].particles[1]: integer expected, got 1.5")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1, 1]}]}', "a distance constraint joins 2 particles, got 3")
  t = TWO .. ' "constraints": [{"type": "spring", "particles": [0, 1]}]}'
  bad_at(t, '"spring"', "constraints[0].type: unknown constraint type 'spring' (expected distance or bend)")
  bad(TWO .. ' "constraints": [{"type": "bend", "particles": [0, 1]}]}', "constraints[0].particles: a bend joins 4 particles (hinge p1 p2, wings p3 p4), got 2")
  bad(TWO .. ' "constraints": [{"particles": [0, 1]}]}', "constraints[0]: missing key 'type'")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1], "compliance": -1}]}', "constraints[0].compliance: must be >= 0")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1], "Compliance": 1}]}', "keys are case-sensitive: 'compliance'")
end)

test("colliders: shapes and their keys", function()
  bad(TWO .. ' "colliders": [{"shape": "cone"}]}', "colliders[0].shape: unknown shape 'cone' (expected plane, sphere, box, capsule or mesh)")
  local t = TWO .. ' "colliders": [{"shape": "sphere", "normal": [0,1,0]}]}'
  bad_at(t, '"normal"', "colliders[0].normal: a sphere takes center radius (and friction, restitution, pose), not 'normal'")
  bad(TWO .. ' "colliders": [{"shape": "sphere", "radius": -1}]}', "colliders[0]: radius must be > 0")
  bad(TWO .. ' "colliders": [{"shape": "box", "half": [1, 0, 1]}]}', "colliders[0]: half extents must be > 0")
  bad(TWO .. ' "colliders": [{"shape": "box", "rotation": [0, 0, 0, 0]}]}', "colliders[0].rotation: rotation must not be zero")
  bad(TWO .. ' "colliders": [{"shape": "plane", "restitution": 2}]}', "restitution must be in [0, 1]")
  bad(TWO .. ' "colliders": [{"shape": "plane", "normal": [0,1,0], "pose": {"position": [0,0,0]}}]}',
      "colliders[0].pose: missing key 'rotation'")
  bad(TWO .. ' "colliders": [{"shape": "sphere", "center": [0,0,0], "pose": {"position": [0,0,0], "rotation": [1,0,0,0]}}]}',
      "a sphere with a pose takes radius in its own frame, not 'center'")
  -- a shape in its own frame is judged by its shape's file, at the collider (not the file's root)
  local POSE = '"pose": {"position": [0,0,0], "rotation": [1,0,0,0]}'
  bad(TWO .. ' "colliders": [{"shape": "capsule", "a": [-1e200,0,0], "b": [1e200,0,0], "radius": 0.1, ' .. POSE .. '}]}',
      "colliders[0]: capsule ends are too far apart")
  bad(TWO .. ' "colliders": [{"shape": "box", "half": [1, 0, 1], ' .. POSE .. '}]}', "colliders[0]: box half extents must be > 0")
  bad(TWO .. ' "colliders": [{"shape": "mesh", "radius": 1, "vertices": [0,0,0, 1,0,0, 0,1,0], "triangles": [0,1,2]}]}',
      "colliders[0].radius: a mesh takes vertices triangles center rotation scale (and friction, restitution, pose), not 'radius'")
end)

test("surfaces, parts and skins", function()
  bad(TWO .. ' "surfaces": [{"triangles": [0, 1]}]}', "surfaces[0].triangles: 2 corners is not a whole number of triangles")
  bad(TWO .. ' "surfaces": [{"triangles": [0, 1, 2]}]}', "surfaces[0].triangles[2]: 2 out of range (0..1)")
  bad(TWO .. ' "parts": [{"name": "a", "first": 1, "count": 2}]}', "parts[0].count: 2 out of range (0..1)")
  bad(TWO .. ' "parts": [{"name": "a", "first": 0, "count": 1}, {"name": "a", "first": 1, "count": 1}]}',
      "parts[1].name: a part named 'a' already exists")
  local t = TWO .. ' "skins": [{"mesh": "nope.obj"}]}'
  bad_at(t, '"nope.obj"', "skins[0].mesh: nope.obj: No such file or directory")
  bad(TWO .. ' "skins": [{"mesh": "x.obj", "bones": 99}]}', "skins[0].bones: 99 out of range (1..16)")
  bad(TWO .. ' "skins": [{"mesh": "x.obj", "particles": [0, 7]}]}', "skins[0].particles[1]: 7 out of range (0..1)")
  bad(TWO .. ' "skins": [{"mesh": "../../../../../../../../etc/passwd"}]}', "outside the allowed folders")
end)

test("snapshot sections are checked too", function()
  bad(TWO .. ' "snapshot": {"world": {"dt": 0}}}', "snapshot.world: dt must be in (0, 10] seconds")
  bad(TWO .. ' "snapshot": {"world": {"solver": "newton"}}}', "snapshot.world.solver: unknown solver 'newton'")
  bad(TWO .. ' "snapshot": {"world": {}, "distance_slots": {"generations": [1, 1], "free": []}}}',
      "snapshot.distance_slots.generations: 2 live slots, but \"constraints\" has 0 entries")
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1]}],\n'
          .. ' "snapshot": {"world": {}, "distance_slots": {"generations": [1, 2], "free": [0]}}}',
      "snapshot.distance_slots.free[0]: slot 0 is live, not free")
  bad(TWO .. ' "snapshot": {"world": {}, "collider_slots": {"generations": [2]}}, "colliders": [{"shape": "plane"}]}',
      "0 live slots, but \"colliders\" has 1 entries")
  -- a dead slot listed twice (the free list's length then does not match: 2 dead, 3 listed)
  bad(TWO .. ' "constraints": [{"type": "distance", "particles": [0, 1]}],\n'
          .. ' "snapshot": {"world": {}, "distance_slots": {"generations": [2, 1, 2], "free": [0, 2, 0]}}}',
      "snapshot.distance_slots.free[2]: slot 0 is listed twice")
  bad(TWO .. ' "snapshot": {"world": {}, "time": -5}}', "snapshot.time: must be >= 0")
  bad(TWO .. ' "skins": [{"mesh": "x.obj", "neighbours": 1}]}', "skins[0].neighbours: 1 out of range (2..32)")
end)

test("files that are not there", function()
  local w = wobble.world{}
  local b, err = w:load_particles("json_errors/nope.json")
  expect.eq(b, nil)
  expect.eq(err, "json_errors/nope.json: No such file or directory")
  write("json_errors/folder.json/x", "")
  b, err = w:load_particles("json_errors/folder.json")
  expect.eq(err, "json_errors/folder.json: is a folder, not a file")
  expect.error(function() w:load_particles("/etc/passwd") end, "outside the allowed folders")
  expect.error(function() w:load_particles() end, "bad argument #1 to 'load_particles' (file name (a string) expected, got no value)")
  local world, e2 = wobble.load("json_errors/nope.json")
  expect.eq(world, nil)
  expect.eq(e2, "json_errors/nope.json: No such file or directory")
end)
