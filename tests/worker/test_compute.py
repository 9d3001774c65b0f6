"""What a job computes on plain data (`worker.compute`): the model loaded from its checkpoint, then the pipeline's
stages, each reported with its share of the job."""

from facaid.generator import generate
from facaid.grammar import Procedure
from facaid.model import save_model


def test_worker_reports_loading_then_the_pipeline_s_stages(tiny, tmp_path):
    from worker.compute import reconstruct as job

    model, tok = tiny
    save_model(model, tok, tmp_path / "ckpt")
    heard = []
    out = job(generate(6).segmentation.to_dict(), str(tmp_path / "ckpt"), k=2,
              progress=lambda f, stage: heard.append((round(f, 6), stage)))
    assert heard[0] == (0.05, "loading the model") and heard[1] == (0.2, "decoding up to 2 candidates")
    assert heard[2] == (0.6, "sizing") and heard[-1] == (1.0, "done")
    assert [f for f, _ in heard] == sorted(f for f, _ in heard)
    Procedure.from_dict(out["procedure"])
