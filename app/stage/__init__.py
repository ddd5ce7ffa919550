"""The offline stage: one body or one scene drawn by the app's own construction on a viser
server of its own, with no control panel and no session, driven by explicit times.

What the exports record and photograph (:mod:`poinsot.app.exports`), what the notebook shows
and what a live session's video button renders: :class:`~.served.Stage` for a preset or a
body, :class:`~.scene_stage.SceneStage` for a lecture scene (:mod:`poinsot.app.lessons`).
"""
