"""The bushing test bench: programmes, the standard campaign, bench files and runs, records, identification."""
