-- wobble.bench: what the benchmark scenes (tests/bench/*.lua) share: which scenes to run
-- (--set scenes=a,b), one table row or one JSON object per scene, the process's resident
-- memory, and the Bullet peer (tests/bench/bullet_cloth.cpp) run as a process of its own.
local M = {}
local args = wobble.args

-- one JSON object per scene for `wobble bench --json`: keys sorted, so runs diff cleanly;
-- a figure that could not be measured is null
function M.json(r)
  local keys = {}
  for k in pairs(r) do keys[#keys + 1] = k end
  table.sort(keys)
  local parts = {}
  for _, k in ipairs(keys) do
    local v = r[k]
    local s
    if v == M.null then s = "null"
    elseif type(v) == "string" then s = string.format("%q", v)
    elseif type(v) == "boolean" then s = tostring(v)
    elseif math.type(v) == "integer" then s = tostring(v)
    elseif v ~= v or v == math.huge or v == -math.huge then s = "null"   -- JSON has no NaN or inf
    else s = string.format("%.6g", v) end
    parts[#parts + 1] = string.format("%q: %s", k, s)
  end
  return "{" .. table.concat(parts, ", ") .. "}"
end

-- a key that is present but unmeasured (nil would drop it from the object)
M.null = setmetatable({}, { __tostring = function() return "null" end })

-- --set scenes=cloth32,tets: only these scenes (names as in the table); default all
function M.want(name)
  local s = args.scenes
  if s == nil or s == "" or s == "all" then return true end
  for n in string.gmatch(tostring(s), "[^,%s]+") do
    if n == name then return true end
  end
  return false
end

-- --frames N (or --set frames=N) overrides every scene's own frame count
function M.frames(default)
  return args.frames or default
end

-- resident memory of this process in bytes, or nil when /proc cannot be read (the
-- sandbox allows it only with --unsafe, as `make bench` runs)
function M.rss()
  local ok, f = pcall(io.open, "/proc/self/status")
  if not ok or not f then return nil end
  local kb
  for line in f:lines() do
    kb = kb or tonumber(line:match("^VmRSS:%s*(%d+)"))
  end
  f:close()
  return kb and kb * 1024
end

-- bytes the process grew by since `before` (an M.rss() figure), per particle; null when
-- unknown. Honest only for the first scene of a process: memory an earlier scene freed
-- is reused without growing the process, so `make bench` runs one scene per process.
function M.bytes_per(before, particles)
  collectgarbage()
  local now = M.rss()
  if not before or not now then return M.null end
  return math.max(0, now - before) / particles
end

-- "double", or "float" in a WB_FLOAT build: seen from what a particle keeps of 0.1
function M.precision()
  local w = wobble.world{}
  local x = w:position(w:particle{ pos = {0.1, 0, 0} })
  return x == 0.1 and "double" or "float"
end

-- the Bullet peer: --set bullet=PATH (the program make bench builds) and --unsafe (a
-- process of its own). cfg: n, frames, substeps, iterations, size, height, mass, radius.
-- With --set bullet_cache=DIR (absolute: a relative path is the --out folder's) the result is kept in DIR (make bench empties it first), so
-- the 2-thread row and the WB_FLOAT build compare with the same Bullet run. Any failure
-- of the peer is an error: a benchmark that silently drops its comparison is worse than
-- none. Returns nil when no peer was asked for.
function M.bullet(cfg)
  local exe = args.bullet
  if exe == nil or exe == "" then return nil end
  local keys = { "n", "frames", "substeps", "iterations", "size", "height", "mass", "radius" }
  local argv, tag = {}, {}
  for _, k in ipairs(keys) do
    if cfg[k] ~= nil then
      argv[#argv + 1] = string.format("%s=%.17g", k, cfg[k])
      tag[#tag + 1] = string.format("%s%.6g", k, cfg[k])
    end
  end
  local cache = args.bullet_cache and (args.bullet_cache .. "/bullet-" .. table.concat(tag, "-") .. ".json")
  local line
  if cache then
    local f = io.open(cache)
    if f then line = f:read("l"); f:close() end
  end
  if not line then
    local cmd = string.format("'%s' %s", tostring(exe):gsub("'", "'\\''"), table.concat(argv, " "))
    local made, p = pcall(io.popen, cmd)
    if not made or not p then
      error("bench: --set bullet=PATH runs the Bullet peer as a process of its own: it needs --unsafe ("
            .. tostring(p) .. ")", 2)
    end
    line = p:read("a")
    local ok, how, code = p:close()
    if not ok then error(string.format("bench: the Bullet peer failed (%s %s): %s", how, code, cmd), 2) end
    line = line:match("^%s*(.-)%s*$")
    if cache then
      local f = io.open(cache, "w")
      if f then f:write(line, "\n"); f:close() end
    end
  end
  local r = {}
  for k, v in line:gmatch('"([%w_]+)":%s*(-?[%d.eE+-]+)') do r[k] = tonumber(v) end
  if not r.ms_per_frame or not r.particles then error("bench: the Bullet peer printed no figures: " .. line, 2) end
  -- the same scene or no comparison: a peer that built another sheet is a bug here
  if r.particles ~= cfg.n * cfg.n then
    error(string.format("bench: the Bullet peer made %d particles, not %d", r.particles, cfg.n * cfg.n), 2)
  end
  return r
end

-- the table: one header per process (--set header=0 leaves it out, so that make bench,
-- one process per scene, prints one table)
local columns = {
  { "scene", "%-12s", "%-12s" }, { "particles", "%9s", "%9d" }, { "constraints", "%11s", "%11d" },
  { "substeps", "%8s", "%8d" }, { "iterations", "%5s", "%5d", "iters" }, { "threads", "%7s", "%7d" },
  { "frames", "%6s", "%6d" }, { "ms_per_frame", "%10s", "%10.3f", "ms/frame" },
  { "ns_per_projection", "%8s", "%8.2f", "ns/proj" }, { "ns_per_projection_solve", "%8s", "%8.2f", "(solve)" },
  { "bytes_per_particle", "%8s", "%8.0f", "B/part" },
  { "bullet_ms_per_frame", "%10s", "%10.3f", "bullet ms" }, { "bullet_ratio", "%7s", "%7.2f", "ratio" },
  { "bullet_ratio_cpu", "%9s", "%9.2f", "cpu ratio" },
}

-- cols: the columns (as `columns` above) of a scene with figures of its own (record.lua);
-- nil: the usual ones
function M.report(r, note, cols)
  -- --set row=NAME: the row's name instead of the scene's (make bench runs a scene again
  -- beside a busy core as another row)
  if args.row ~= nil and args.row ~= "" then r.scene = tostring(args.row) end
  if args.json_file then   -- make bench JSON=FILE: the rows as JSON lines too (--unsafe)
    local f = assert(io.open(args.json_file, "a"))
    f:write(M.json(r), "\n")
    f:close()
  end
  if args.json then
    print(M.json(r))
    return
  end
  local head, row = {}, {}
  for _, c in ipairs(cols or columns) do
    local key, hfmt, vfmt, label = c[1], c[2], c[3], c[4] or c[1]
    head[#head + 1] = string.format(hfmt, label)
    local v = r[key]
    if v == nil or v == M.null or (type(v) == "number" and v ~= v) then row[#row + 1] = string.format(hfmt, "-")
    else row[#row + 1] = string.format(vfmt, v) end
  end
  if args.header ~= 0 and not M.printed_header then
    print(table.concat(head, " "))
    M.printed_header = true
  end
  print(table.concat(row, " ") .. (note and ("  " .. note) or ""))
end

return M
