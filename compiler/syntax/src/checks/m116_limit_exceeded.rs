//! M116 `limit-exceeded`: A file is too large, too deeply nested, includes nest too deeply, or a queue or port group is too long.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "M116",
    name: "limit-exceeded",
    severity: Severity::Error,
    summary:
        "A file is too large, too deeply nested, includes nest too deeply, or a queue or port group is too long.",
    explanation:
        "The checker refuses input that would exhaust memory or the stack instead of crashing: files
over 256 MiB, elements nested more than 256 deep, includes nested more than 32 deep,
group types instantiated more than 64 deep, queues (`queue=`) of more than 65536 values
(allocated in full when a run starts), flexible port groups (`<port count=>`) of more
than 4096 ports (each made when the module is created).

Bad:
    <group name=\"g\"><group name=\"g\"><group name=\"g\"> ... (300 levels)

Fix: flatten the structure; real models are far below these limits.",
    fixtures: "compiler/syntax/src/checks/m116_limit_exceeded",
};
