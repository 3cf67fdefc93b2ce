% GNU Octave's `ga` (Octave-Forge package ga 0.10.3) on an imusysid problem
% file, with the paper's settings, printing one JSON line shaped like
% `imusysid fit --format=json`.
%
% Usage: octave-cli -q --no-init-file octave_ga.m PROBLEM.csv [SEED]
%            [OBJECTIVE] [VECTORIZED]
%   SEED        seed of rand/randn ("state"), default 1
%   OBJECTIVE   direct (default: sum over the samples) or gram (see Rmse)
%   VECTORIZED  on (default: the population is scored in one call) or off
%               (one call per individual, as MATLAB's default does)
%
% Settings: PopulationSize 250 and CrossoverFcn @crossoverscattered (the
% paper's), EliteCount 13 and Generations 400 (MATLAB's defaults for 250
% individuals and 4 variables, where Octave's would be 2 and 100). Octave's
% ga accepts bounds but ignores them (docs/matlab-ga.md section 6), so the
% box is given as PopInitRange: the initial population is uniform in the box
% and the Gaussian mutation's scale is the box's width; later generations may
% leave the box. It has no stall test: it always runs all 400 generations.
% The objective is the paper's OF, the RMSE of f minus equation 9.

1;  % a script file, not a function file

function [data, meta] = ReadProblem (path)
  text = fileread (path);
  if (numel (text) >= 3 && all (double (text(1:3)) == [239 187 191]))
    text = text(4:end);
  endif
  lines = strsplit (text, "\n");
  meta = containers.Map ();
  header = 0;
  for i = 1:numel (lines)
    l = strtrim (lines{i});
    if (isempty (l))
      continue;
    endif
    if (l(1) == "#")
      tok = regexp (l, '^#\s*([^:]*[^:\s])\s*:\s+(.*)$', "tokens", "once");
      if (! isempty (tok))
        meta(tok{1}) = strtrim (tok{2});
      endif
      continue;
    endif
    header = i;
    break;
  endfor
  if (header == 0)
    error ("%s: no header line", path);
  endif
  names = strtrim (strsplit (strtrim (lines{header}), ","));
  values = dlmread (path, ",", header, 0);
  need = {"t", "f", "omega", "omega_dot", "v"};
  for k = 1:numel (need)
    c = find (strcmp (names, need{k}));
    if (isempty (c))
      error ("%s: missing column '%s'", path, need{k});
    endif
    data.(need{k}) = values(:, c);
  endfor
  data.g = 9.80665;
  if (isKey (meta, "gravity"))
    data.g = str2double (meta("gravity"));
  endif
endfunction

% The paper's OF for each row of X = [r beta alpha mu] (m, deg, deg, 1/m):
% sqrt(mean((f - fbar).^2)) with fbar = g sin(alpha) - r w^2 cos(beta-alpha)
% + r wdot sin(beta-alpha) - mu sign(v) v^2 (equation 9), written as
% fbar = C(X) * M with the coefficient rows C = [g sin(alpha), r cos(beta -
% alpha), r sin(beta - alpha), mu] and the regressor rows M = [1; -w^2; wdot;
% -sign(v) v^2], so the whole population costs one matrix product.
% objective "direct" sums the n squared residuals of every individual;
% "gram" uses the 5 x 5 Gram matrix of [M' f] instead (the same number up to
% rounding, O(1) per individual: how imusysid's paper model evaluates it).
function C = Coefficients (X, g)
  a = X(:, 3) * pi / 180;
  ba = X(:, 2) * pi / 180 - a;
  C = [g * sin(a), X(:, 1) .* cos(ba), X(:, 1) .* sin(ba), X(:, 4)];
endfunction

function of = Rmse (X, d)
  global kEvaluations;
  kEvaluations += rows (X);
  C = Coefficients (X, d.g);
  if (d.gram)
    sse = d.G(5, 5) - 2 * C * d.G(1:4, 5) + sum ((C * d.G(1:4, 1:4)) .* C, 2);
    of = sqrt (max (sse, 0) / d.n);
  else
    of = sqrt (sumsq (d.f' - C * d.M, 2) / d.n);
  endif
endfunction

function s = JsonString (text)
  s = ["\"" strrep(strrep (text, "\\", "\\\\"), "\"", "\\\"") "\""];
endfunction

function s = MetaOr (meta, key, default)
  if (isKey (meta, key))
    s = meta(key);
  else
    s = default;
  endif
endfunction

args = argv ();
if (numel (args) < 1)
  fprintf (stderr, "usage: octave_ga.m PROBLEM.csv [SEED] [on|off]\n");
  exit (2);
endif
path = args{1};
seed = 1;
if (numel (args) >= 2)
  seed = str2double (args{2});
endif
objective = "direct";
if (numel (args) >= 3)
  objective = args{3};
endif
vectorized = "on";
if (numel (args) >= 4)
  vectorized = args{4};
endif
if (! any (strcmp (objective, {"direct", "gram"})))
  fprintf (stderr, "octave_ga: objective must be direct or gram, not '%s'\n",
           objective);
  exit (2);
endif
pkg load ga;
try
  [d, meta] = ReadProblem (path);
catch err
  fprintf (stderr, "octave_ga: %s\n", err.message);
  exit (2);
end_try_catch
d.n = numel (d.t);
d.M = [ones(1, d.n); -(d.omega .^ 2)'; d.omega_dot'; -(sign (d.v) .* d.v .^ 2)'];
d.gram = strcmp (objective, "gram");
if (d.gram)
  Mf = [d.M; d.f'];
  d.G = Mf * Mf';
endif

lb = [0, -180, -15, 0];
ub = [0.5, 180, 15, 1];
options = gaoptimset ("PopulationSize", 250,
                      "CrossoverFcn", @crossoverscattered,
                      "EliteCount", 13,
                      "Generations", 400,
                      "PopInitRange", [lb; ub],
                      "Vectorized", vectorized);
rand ("state", seed);
randn ("state", seed);
global kEvaluations;
kEvaluations = 0;
t0 = tic ();
[x, fval] = ga (@(X) Rmse (X, d), 4, [], [], [], [], lb, ub, [], options);
wall_ms = 1000 * toc (t0);

% r < 0 is the same point as (|r|, beta + 180): report it in the box's
% convention and keep the raw values.
raw = x;
if (x(1) < 0)
  x(1) = -x(1);
  x(2) = x(2) + 180;
endif
x(2) = mod (x(2) + 180, 360) - 180;
if (any (raw < lb | raw > ub))
  left_box = "true";
else
  left_box = "false";
endif
ga_info = pkg ("list", "ga");
n = numel (d.t);
printf (["{\"log\":%s,\"model\":\"paper\",\"estimator\":\"octave-ga\"," ...
         "\"seed\":%d,\"plane\":%s,\"velocity\":%s," ...
         "\"segment\":{\"t_start_s\":%.17g,\"t_end_s\":%.17g,\"samples\":%d}," ...
         "\"r_m\":%.17g,\"beta_deg\":%.17g,\"alpha_deg\":%.17g,\"mu\":%.17g," ...
         "\"raw_parameters\":{\"r_m\":%.17g,\"beta_deg\":%.17g," ...
         "\"alpha_deg\":%.17g,\"mu\":%.17g}," ...
         "\"rmse\":%.17g,\"final_cost\":%.17g,\"evaluations\":%d," ...
         "\"iterations\":400,\"wall_ms\":%.6f,\"termination\":\"max_generations\"," ...
         "\"details\":{\"tool\":%s,\"population\":250,\"elite\":13," ...
         "\"generations\":400,\"objective\":%s,\"vectorized\":%s,\"bounds\":\"PopInitRange only\"," ...
         "\"left_box\":%s}}\n"],
        JsonString (path), seed, JsonString (MetaOr (meta, "plane", "unknown")),
        JsonString (MetaOr (meta, "velocity", "unknown")), d.t(1), d.t(end), n,
        x(1), x(2), x(3), x(4), raw(1), raw(2), raw(3), raw(4),
        fval, 0.5 * n * fval ^ 2, kEvaluations, wall_ms,
        JsonString (["GNU Octave " version() ", ga " ga_info{1}.version]),
        JsonString (objective), JsonString (vectorized), left_box);
