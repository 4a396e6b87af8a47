"""What a term sees (context, contract, materials) and the energy terms themselves."""
