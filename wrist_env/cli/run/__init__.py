"""How the `wrist-bench` commands run: one module per declaring module of `wrist_env.cli` (participants,
figures, studies, identification), each function named after its command. A command's parser names its
function as "module:function" (its `run` default); `wrist_env.cli.main` imports the module only once the
command's arguments have parsed, so a usage error or `--help` loads none of what the commands run."""

__all__: list[str] = []  # the modules are the API: nothing is imported here
