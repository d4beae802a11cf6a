"""The web app (``arena web``; extra ``arena[web]``): runs, results, replays, live views.

- :mod:`arena.web.store`: the run store, read safely;
- :mod:`arena.web.api`: the REST and WebSocket API;
- :mod:`arena.web.pages`: the NiceGUI pages;
- :mod:`arena.web.server`: the app, its token gate, and how it is served;
- ``static/arena_view.js``: the live and replay canvas.
"""
