from urdftool.cli import main

main()
